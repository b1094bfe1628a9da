#include "delayspec/orbit_shooting.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "delayspec/errors.hpp"

namespace delayspec {

std::vector<int> shooting_levels(const HistoryGrid& grid, int coarse_N, int refinement) {
  if (coarse_N < 1) throw BadInput("`orbit_coarse_N = " + std::to_string(coarse_N) + "`: must be >= 1");
  if (refinement < 2) throw BadInput("shooting levels: refinement " + std::to_string(refinement) + " must be >= 2");
  // Valid N: with tau / T = p / q (aligned grid, lowest terms) N must be a multiple of p, and
  // N / K_1 = p / q gives p = N / gcd(N, K_1). A fractional delay takes any N.
  const long multiple =
      grid.aligned() ? grid.N / std::gcd(static_cast<long>(grid.N), static_cast<long>(grid.steps_per_period)) : 1;
  std::vector<int> Ns{grid.N};
  for (;;) {
    const double target = static_cast<double>(Ns.back()) / refinement;
    if (target < coarse_N) break;  // so that N < refinement coarse_N is exactly one level
    const long coarser = multiple * std::max(1L, std::lround(target / static_cast<double>(multiple)));
    if (coarser >= Ns.back()) break;
    Ns.push_back(static_cast<int>(coarser));
  }
  std::reverse(Ns.begin(), Ns.end());
  return Ns;
}

}  // namespace delayspec
