#pragma once
// The stability verdict of every point of a continued branch (issue 32, item 1): stable,
// unstable or undecided, as floquet's (error_bars.hpp), for the N -> infinity branch.
//
// The branch at the finest N changes stability only where it has a bifurcation (a multiplier
// through the circle, or a grazing, where the multipliers jump): between two of them the number
// of unstable multipliers is constant. In the limit the same holds with each bifurcation moved
// from its location p_N at the finest N to its extrapolated location p_inf, known to within its
// error estimate e. So a point at p has the finest branch's stability in the limit unless p lies
// in some bifurcation's interval [min(p_N, p_inf) - e, max(p_N, p_inf) + e], where it is
// undecided. What this rests on, checked before any point is decided:
//   * every bifurcation has a finite error estimate (three levels or more, its order checked:
//     richardson.hpp); one without is somewhere unknown in the limit, so no point is decided;
//   * every bifurcation of a coarser level was matched to one of the finest (extrapolate_
//     bifurcations); one that was not may be missing from the finest branch, so no point is
//     decided.
// A multiplier that stays inside the circle at every level but would cross it in the limit
// within the range would have to cross it at the finest N too, near p_inf, unless it crosses
// beyond the range's end at that N: what no finite set of levels can rule out (docs/continuation.md).
#include <string>
#include <vector>

#include "delayspec/continuation.hpp"
#include "delayspec/error_bars.hpp"

namespace delayspec {

struct BranchVerdicts {
  std::vector<StabilityVerdict> verdicts;  // per point of the finest branch
  std::string note;                        // why every point is undecided, or how many are and why
};

// points: the finest branch's; estimates: extrapolate_bifurcations(Ns, by_N, ...) of its
// bifurcations; by_N[i]: the bifurcations of the branch at Ns[i], the finest last. Fewer than
// three levels: every point undecided (no error bar). BadInput: Ns and by_N differ in size.
BranchVerdicts branch_verdicts(const std::vector<ContinuationPoint>& points,
                               const std::vector<BifurcationEstimate>& estimates, const std::vector<int>& Ns,
                               const std::vector<std::vector<Bifurcation>>& by_N);

}  // namespace delayspec
