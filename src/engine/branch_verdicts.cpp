#include "delayspec/branch_verdicts.hpp"

#include <algorithm>
#include <cmath>

namespace delayspec {

BranchVerdicts branch_verdicts(const std::vector<ContinuationPoint>& points,
                               const std::vector<BifurcationEstimate>& estimates, const std::vector<int>& Ns,
                               const std::vector<std::vector<Bifurcation>>& by_N) {
  if (Ns.size() != by_N.size())
    throw BadInput("branch_verdicts: " + std::to_string(Ns.size()) + " levels but " + std::to_string(by_N.size()) +
                   " lists of bifurcations");
  BranchVerdicts out;
  out.verdicts.assign(points.size(), StabilityVerdict::undecided);
  if (by_N.size() < 3) {
    out.note = "a verdict needs the bifurcations' error bars: continue_Ns with three levels or more";
    return out;
  }
  for (const BifurcationEstimate& e : estimates)
    if (!std::isfinite(e.error_estimate)) {
      out.note = "the " + to_string(e.type) + " at " + format_number(e.parameter) +
                 " has no error bar, so where the N -> infinity branch changes stability is not known";
      return out;
    }
  // A coarser level's bifurcation that no finest one took (extrapolate_bifurcations matches each
  // finest bifurcation with at most one per level, so a level with more than were matched there
  // has one left over).
  for (size_t level = 0; level + 1 < by_N.size(); ++level) {
    const size_t matched = std::count_if(estimates.begin(), estimates.end(), [&](const BifurcationEstimate& e) {
      return std::find(e.Ns.begin(), e.Ns.end(), Ns[level]) != e.Ns.end();
    });
    if (by_N[level].size() > matched) {
      out.note = "N = " + std::to_string(Ns[level]) + " has " + std::to_string(by_N[level].size()) +
                 " bifurcations on its branch, " + std::to_string(matched) +
                 " of them matched at the finest N: the finest branch may miss a change of stability";
      return out;
    }
  }
  size_t undecided = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const double p = points[i].parameter;
    const bool near = std::any_of(estimates.begin(), estimates.end(), [p](const BifurcationEstimate& e) {
      return p >= std::min(e.parameter, e.extrapolated) - e.error_estimate &&
             p <= std::max(e.parameter, e.extrapolated) + e.error_estimate;
    });
    if (near) {
      ++undecided;
      continue;
    }
    out.verdicts[i] = points[i].stable() ? StabilityVerdict::stable : StabilityVerdict::unstable;
  }
  out.note = std::to_string(undecided) + " of " + std::to_string(points.size()) +
             " points undecided: within a bifurcation's interval between its location at the finest N and its "
             "extrapolated one, widened by its error estimate";
  return out;
}

}  // namespace delayspec
