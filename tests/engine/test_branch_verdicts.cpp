// The verdicts of a branch's points (branch_verdicts.hpp) and the humps of H along an orbit
// (detail/contact_peaks.hpp), on inputs built by hand whose answers are known.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "delayspec/branch_verdicts.hpp"
#include "delayspec/detail/contact_peaks.hpp"

using namespace delayspec;

namespace {

ContinuationPoint point(double p, int unstable) {
  ContinuationPoint pt;
  pt.parameter = p;
  pt.unstable = unstable;
  return pt;
}

Bifurcation at(double p, BifurcationType type = BifurcationType::neimark_sacker) {
  Bifurcation b;
  b.type = type;
  b.parameter = p;
  return b;
}

// A branch over p = 0, 0.1, .., 1.0 that loses stability at 0.5 (finest N), extrapolated to 0.48
// +- 0.01: every point in [0.47, 0.51] is undecided, the others take the finest branch's stability.
TEST(BranchVerdicts, PointsNearAnExtrapolatedBifurcationAreUndecidedTheOthersKeepTheirSide) {
  std::vector<ContinuationPoint> points;
  for (int i = 0; i <= 20; ++i) points.push_back(point(0.05 * i, 0.05 * i > 0.5 ? 2 : 0));
  BifurcationEstimate e;
  e.type = BifurcationType::neimark_sacker;
  e.Ns = {100, 200, 400};
  e.parameters = {0.53, 0.508, 0.5};
  e.parameter = 0.5;
  e.extrapolated = 0.48;
  e.error_estimate = 0.01;
  const std::vector<std::vector<Bifurcation>> by_N = {{at(0.53)}, {at(0.508)}, {at(0.5)}};
  const BranchVerdicts v = branch_verdicts(points, {e}, {100, 200, 400}, by_N);
  ASSERT_EQ(v.verdicts.size(), points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const double p = points[i].parameter;
    const StabilityVerdict expected = p >= 0.47 && p <= 0.51 ? StabilityVerdict::undecided
                                      : p < 0.5              ? StabilityVerdict::stable
                                                             : StabilityVerdict::unstable;
    EXPECT_EQ(v.verdicts[i], expected) << "p = " << p << ": " << v.note;
  }
  EXPECT_NE(v.note.find("1 of 21"), std::string::npos) << v.note;  // p = 0.5 only (0.45, 0.55 outside)
}

// What the verdicts rest on, each missing in turn: no point is decided.
TEST(BranchVerdicts, WithoutBarsOrWithAnUnmatchedCoarseBifurcationNothingIsDecided) {
  const std::vector<ContinuationPoint> points = {point(0, 0), point(1, 0)};
  BifurcationEstimate e;
  e.Ns = {100, 200, 400};
  e.parameter = e.extrapolated = 0.5;
  e.error_estimate = 1e-6;
  const std::vector<std::vector<Bifurcation>> by_N = {{at(0.5)}, {at(0.5)}, {at(0.5)}};
  auto all_undecided = [](const BranchVerdicts& v) {
    for (StabilityVerdict s : v.verdicts)
      if (s != StabilityVerdict::undecided) return false;
    return !v.note.empty();
  };
  // two levels: no bar at all
  EXPECT_TRUE(all_undecided(branch_verdicts(points, {e}, {200, 400}, {{at(0.5)}, {at(0.5)}})));
  // a bifurcation without an error bar
  BifurcationEstimate no_bar = e;
  no_bar.error_estimate = INFINITY;
  EXPECT_TRUE(all_undecided(branch_verdicts(points, {no_bar}, {100, 200, 400}, by_N)));
  // a coarse level's second bifurcation that the finest branch does not have
  const BranchVerdicts extra =
      branch_verdicts(points, {e}, {100, 200, 400}, {{at(0.5), at(0.9, BifurcationType::fold)}, {at(0.5)}, {at(0.5)}});
  EXPECT_TRUE(all_undecided(extra));
  EXPECT_NE(extra.note.find("N = 100"), std::string::npos) << extra.note;
  // and with everything in place both points are decided
  const BranchVerdicts decided = branch_verdicts(points, {e}, {100, 200, 400}, by_N);
  EXPECT_EQ(decided.verdicts[0], StabilityVerdict::stable);
  EXPECT_EQ(decided.verdicts[1], StabilityVerdict::stable);
  EXPECT_THROW(branch_verdicts(points, {e}, {100, 200}, by_N), BadInput);
}

// H along one period sampled at K nodes, with each step's maximum from a fine sampling of the
// same function (what the cubic Hermite maximum approximates).
struct Profile {
  std::vector<double> node, step_max;
};
template <class F>
Profile sample(F&& H, int K) {
  Profile out;
  for (int l = 0; l < K; ++l) {
    out.node.push_back(H(double(l) / K));
    double m = -INFINITY;
    for (int s = 0; s <= 16; ++s) m = std::max(m, H((l + s / 16.0) / K));
    out.step_max.push_back(m);
  }
  return out;
}

// Two humps of heights 0.3 and c, separated by free flight (H down to -1): the second is a
// separate region whatever c is, so second_max = c, and the regions are 1 or 2 by its sign. A
// wiggle on top of the first hump (the stiff contact spring) is neither a hump nor a region.
TEST(ContactPeaks, TheSecondHumpIsSeenThroughZeroAndAWiggleInContactIsNot) {
  const double pi = std::numbers::pi;
  for (double c : {-0.2, -1e-3, 1e-3, 0.2}) {
    auto H = [c, pi](double t) {
      const double wiggle = 0.01 * std::sin(200 * pi * t) * std::exp(-std::pow((t - 0.25) / 0.01, 2));  // where H > 0.2
      const double hump1 = 1.3 * std::exp(-std::pow((t - 0.25) / 0.05, 2)) + wiggle;
      const double hump2 = (1 + c) * std::exp(-std::pow((t - 0.7) / 0.05, 2));
      return -1 + hump1 + hump2;
    };
    const detail::ContactPeaks peaks = detail::contact_peaks(sample(H, 400).node, sample(H, 400).step_max);
    EXPECT_NEAR(peaks.second_max, c, 2e-3) << "c = " << c;  // the step maximum's sampling error
    EXPECT_EQ(peaks.regions, c > 0 ? 2 : 1) << "c = " << c;
  }
  // One hump, no second: -infinity; all below 0: no region.
  auto one = [](double t) { return -0.5 + 0.4 * std::cos(2 * std::numbers::pi * t); };
  const detail::ContactPeaks none = detail::contact_peaks(sample(one, 100).node, sample(one, 100).step_max);
  EXPECT_EQ(none.second_max, -INFINITY);
  EXPECT_EQ(none.regions, 0);
}

}  // namespace
