#pragma once
// Error bars for the Floquet multipliers computed at one resolution N, and the stability verdict
// they allow (issue 32; design.md 1.8). The value at N is what a user reads; how far it is from
// the N -> infinity value is estimated from two coarser levels, N/4 and N/2 (the largest valid
// grids at or below them), with the convergence study's rules (convergence.hpp): tracks matched
// across the levels, Richardson on them with every column checked against its expected order
// (richardson.hpp). The coarse levels cost about 1/4 + 1/2 of the solve at N for the Krylov
// solvers (linear in N) and 1/64 + 1/8 for dense (cubic). Why not N/16 and N/4 (1/16 + 1/4, until
// issue 58): the coarsest level must be in the asymptotic range for its order to show, and N/16
// seldom is; measured on four charts (N = 200), the undecided points fell from 687, 318, 15 and
// 252 to 201, 102, 6 and 68, and the paper's impacting orbit (aligned with its contacts) is
// decided from N = 1600 on instead of 3200.
//
// Per multiplier mu_N:
//   extrapolated       where the order is shown (column 0 consistent with its expected order over
//                      the three levels): the Richardson value and its error estimate e_x (the
//                      last correction: an overestimate of its error, richardson.hpp);
//   error_estimate     of mu_N itself: |mu_N - extrapolated| + e_x; without an extrapolation the
//                      estimate of column 0 (from its last differences, max(d_last, d_prev);
//                      infinity when they grow or only two levels succeeded).
//
// Verdict, each multiplier taken at its best value x (the extrapolated one where there is one,
// else mu_N) with that value's bar e. It rests on the leading multiplier at N (and any of its
// modulus, its conjugate): the spectral radius, whose N -> infinity limit bounds every other
// multiplier's, so a tiny multiplier without a bar (x' = -x + 1e-8 x(t - 1): 6e-10, the levels
// disagree) does not hold the verdict back:
// A multiplier that is not resolved at N (multiplier_resolved, from the level's accuracy) has no
// bar and no part in the verdict.
//   unstable   some |x| - e > 1;
//   stable     |x_1| + e_1 < 1 for the leading ones;
//   undecided  otherwise: the unit circle lies within a leading bar (or it is infinite). deciding_N is
//              then the N at which the bar of mu_N would shrink below the distance | |x| - 1 |,
//              from error ~ N^-p with p the expected order (an order observed over three levels
//              may be pre-asymptotic); 0 when no N can tell (an infinite bar, or |x| = 1).
#include <complex>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "delayspec/convergence.hpp"

namespace delayspec {

enum class StabilityVerdict { stable, unstable, undecided };
std::string to_string(StabilityVerdict verdict);  // "stable", "unstable", "undecided"

// How far apart the coarser levels are: N/4 and N/2 (halving, the default), or N/16 and N/4
// (N/8 and N/4 below N = 256: quartering, the rule before issue 58). An autonomous orbit's
// levels keep quartering: its steps per period, round(N T / tau), do not halve with N (62, 125,
// 250 at N = 25, 50, 100 for Mackey-Glass, tau = 8), so its levels are not nested either way, and
// over N = 25, 50, 100 the period's differences fall as a plateau's (no bar; measured) where 12,
// 25, 100 show order 2 (autonomous_floquet.cpp; nesting them is issue 59's).
enum class LevelSpacing { halving, quartering };

// The coarser levels for N, coarsest first: the largest N' <= N / 2^j (halving) or N / 4^j
// (quartering, N / 8 for j = 2 below N = 256) with valid(N') true (the grid's rule: a
// delay/period ratio may need multiples), j = 2, 1; a level below `min_N` is left out.
std::vector<int> coarser_levels(int N, const std::function<bool(int)>& valid, int min_N = 4,
                                LevelSpacing spacing = LevelSpacing::halving);

struct MultiplierErrorBar {
  double error_estimate = 0;  // of mu_N, absolute (infinity: none possible)
  std::optional<std::complex<double>> extrapolated;
  double extrapolated_error = 0;  // of `extrapolated`, absolute
};

struct ErrorBars {
  std::vector<int> Ns;                     // the levels, coarsest first; the last is N
  std::vector<std::string> failures;       // per level: why it failed ("" when it did not)
  std::vector<MultiplierErrorBar> bars;    // in the order of the multipliers at N
  std::vector<bool> resolved;              // per multiplier at N (multiplier_resolved; all true without accuracies)
  std::optional<double> order;             // observed order of the leading track, when settled
  double expected_order = 2;               // the expansion's leading order (used when none is observed)
  StabilityVerdict verdict = StabilityVerdict::undecided;
  long deciding_N = 0;                     // undecided: header comment
  std::string note;                        // what limits the bars, in words with the numbers
};

// levels[i] was computed at Ns[i] (coarsest first); the last is the solve at N (its multipliers
// are the ones barred, in their order) and must have succeeded. A failed coarse level leaves the
// bars to the others (two levels: no order check, infinite bars). richardson: the error expansion
// (order 2, step 2 for the trapezoid on a smooth or event-located problem).
ErrorBars error_bars(const std::vector<int>& Ns, const std::vector<LevelResult>& levels,
                     const RichardsonOptions& richardson);

}  // namespace delayspec
