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
    if (target < coarse_N) break;
    const long coarser = multiple * std::max(1L, std::lround(target / static_cast<double>(multiple)));
    if (coarser >= Ns.back()) break;
    Ns.push_back(static_cast<int>(coarser));
  }
  // Then coarse_N itself (the smallest valid N >= it) unless that is more than half the last level:
  // the guess is simulated at about coarse_N whatever N is (the attractor a run from the initial
  // history settles on is chosen on one grid, not on one that depends on where N falls between
  // powers of 8), and its periods cost a half to an eighth of those at the last level's N.
  const long coarsest = multiple * ((coarse_N + multiple - 1) / multiple);
  if (2 * coarsest <= Ns.back()) Ns.push_back(static_cast<int>(coarsest));
  std::reverse(Ns.begin(), Ns.end());
  return Ns;
}

}  // namespace delayspec
