#pragma once
// The humps of H(y(t)) along a periodic orbit, for continuation's grazing of a second contact
// region (issue 32, item 4): on an orbit already in contact (max H > 0) a new contact region
// appears where another hump of H rises through 0, which the sign of max H does not see.
//
// Input, over one map of K steps (cyclic: step K - 1 ends at node 0): node[l] = H at node l and
// step_max[l] = the largest H over step l (>= node[l], node[l + 1]; the cubic Hermite maximum,
// cubic_hermite.hpp). A hump is a local maximum of step_max (ties to the right count once); its
// saddle is the lowest node on the way to a higher hump, on the better of its two sides (the
// topographic key col). Two humps are separate contact regions exactly when the col between them
// lies below 0 (H <= 0 on a node between them: free flight), so:
//   second_max   the highest hump, other than the highest one, whose col lies below 0: the test
//                function of the second region's grazing (-infinity when there is none);
//   regions      the number of contact regions, humps above 0 with a col below 0, plus the highest
//                hump when it is above 0.
// A wiggle of H inside one contact region (the stiff contact spring makes them) has its col above
// 0 and is neither. Cost O(K) per hump.
#include <cmath>
#include <vector>

namespace delayspec::detail {

struct ContactPeaks {
  double second_max = -INFINITY;
  int regions = 0;
};

inline ContactPeaks contact_peaks(const std::vector<double>& node, const std::vector<double>& step_max) {
  ContactPeaks out;
  const long K = static_cast<long>(step_max.size());
  if (K < 3 || static_cast<long>(node.size()) != K) return out;
  auto at = [K](long l) { return ((l % K) + K) % K; };
  std::vector<long> humps;  // a tie is one hump, taken at its last step (the wrap included)
  for (long l = 0; l < K; ++l)
    if (step_max[l] > step_max[at(l - 1)] && step_max[l] >= step_max[at(l + 1)]) humps.push_back(l);
  if (humps.empty()) return out;  // H constant along the orbit
  long top = humps.front();
  for (long l : humps)
    if (step_max[l] > step_max[top]) top = l;
  if (step_max[top] > 0) out.regions = 1;
  for (long l : humps) {
    if (l == top) continue;
    // The lowest node on the way to a higher hump, leftwards (nodes l, l - 1, ...) and rightwards
    // (nodes l + 1, l + 2, ...); the walk ends at the highest hump at the latest.
    double left = node[l], right = node[at(l + 1)];
    for (long i = l - 1; step_max[at(i)] <= step_max[l] && at(i) != l; --i) left = std::min(left, node[at(i)]);
    for (long i = l + 1; step_max[at(i)] <= step_max[l] && at(i) != l; ++i) right = std::min(right, node[at(i + 1)]);
    const double col = std::max(left, right);
    if (!(col <= 0)) continue;
    out.second_max = std::max(out.second_max, step_max[l]);
    if (step_max[l] > 0) ++out.regions;
  }
  return out;
}

}  // namespace delayspec::detail
