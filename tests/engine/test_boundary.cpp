// The curve follower of boundary.hpp on test functions written here, no model: what the
// corrector and the start check do on a known zero set (the command's tests, tests/cli/
// test_cli_boundary.cpp, check it on models against exact curves).
// - g = u^2 + v^2 - 1: every point on the circle to the tolerance, through the turning point
//   u = 1 and back to u_from, in fewer steps and evaluations than the chord corrector needs
//   (the Broyden update's gain).
// - where the curve meets a curve of the other kind (the sign change of BoundarySample::other
//   between two points): located on the curve to the tolerance, passed, named by the type.
// - on_boundary_curve: a point of the true curve between two samples is on it although the
//   chord misses it by more than the tolerance (its sagitta); a point off by more is not.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "delayspec/boundary.hpp"

using namespace delayspec;

namespace {

BoundarySample circle(double u, double v) {
  BoundarySample s;
  s.defined = true;
  s.value = u * u + v * v - 1;
  return s;
}

}  // namespace

TEST(Boundary, ACircleIsFollowedThroughItsTurningPointToTheTolerance) {
  BoundaryOptions o;
  o.x_from = 0.6, o.x_to = 1.5, o.y_from = -1.2, o.y_to = 1.2;
  const BoundaryCurve c = trace_boundary(circle, -0.8, o);
  EXPECT_EQ(c.end, BoundaryEnd::from) << c.note;
  ASSERT_GE(c.points.size(), 5u);
  double u_max = 0;
  for (const BoundaryPoint& p : c.points) {
    u_max = std::max(u_max, p.x);
    // A point is corrected until its last step is <= 1e-10 in the scaled plane (ranges 0.9 and
    // 2.4); with the superlinear corrector the step after would be far smaller: |g| = 2 r |dr|
    // <= ~1e-9.
    EXPECT_NEAR(p.x * p.x + p.y * p.y, 1.0, 1e-9) << p.x << " " << p.y;
  }
  EXPECT_GT(u_max, 0.999);
  EXPECT_EQ(c.points.back().x, 0.6);
  EXPECT_NEAR(c.points.back().y, 0.8, 1e-9);
  // The cost: the steps keep the chord within chord_error (1e-4) of the circle and shrink after a
  // correction of 6 iterations or more. Measured: 59 points and 235 evaluations of g (4 per point,
  // the corrector's iterations alone: the tangent from the last points, the gradient the
  // corrector's Broyden row); g again at the converged point and a gradient by differences
  // would add 3 a point (412); the chord corrector without the Broyden update converges so slowly
  // that the steps shrink to 1000 points (max_points) in 5763 evaluations. The bounds lie
  // between: either loss fails them.
  EXPECT_LE(c.points.size(), 80u);
  EXPECT_LE(c.evaluations, 300);
  EXPECT_TRUE(c.codim2.empty());  // (no other kind's test function: never a meeting)
}

TEST(Boundary, WhereTheCurveMeetsACurveOfTheOtherKindIsLocatedAndPassed) {
  // The circle as above, now a period-doubling curve whose orbit grazes where v = 0.6 (the other
  // kind's test function, max H, = v - 0.6): on the upper half at u = 0.8.
  const auto g = [](double u, double v) {
    BoundarySample s = circle(u, v);
    s.angle = std::numbers::pi;
    s.other = v - 0.6;
    s.other_type = BifurcationType::period_doubling;
    s.other_angle = s.angle;
    return s;
  };
  BoundaryOptions o;
  o.x_from = 0.6, o.x_to = 1.5, o.y_from = -1.2, o.y_to = 1.2;
  const BoundaryCurve c = trace_boundary(g, -0.8, o);
  EXPECT_EQ(c.end, BoundaryEnd::from) << c.note;  // passed, not an end
  ASSERT_EQ(c.codim2.size(), 1u);
  const Codim2Point& q = c.codim2[0];
  EXPECT_EQ(q.kind, Codim2Kind::grazing_meets);
  EXPECT_EQ(q.met, BifurcationType::period_doubling);
  EXPECT_EQ(to_string(q), "grazing meets period-doubling");
  // The bracket along the chord is closed to the tolerance, 1e-10 of the ranges (<= 2.4e-10),
  // on points each on the circle to |g| <= ~1e-9 (above): v to 1e-9, u = sqrt(1 - v^2) to 2e-9.
  EXPECT_NEAR(q.y, 0.6, 1e-9);
  EXPECT_NEAR(q.x, 0.8, 2e-9);
  EXPECT_EQ(q.angle, std::numbers::pi);
}

TEST(Boundary, AStartBetweenTwoSamplesOfACurvedCurveIsOnIt) {
  // Samples of the unit circle's upper half every 10 degrees; the true curve between two of them
  // lies 1 - cos 5 deg = 3.8e-3 above the chord at the middle.
  BoundaryCurve c;
  for (int deg = 20; deg <= 160; deg += 10) {
    const double t = deg * std::numbers::pi / 180;
    c.points.push_back({std::cos(t), std::sin(t), NAN, 0});
  }
  const double mid = 85 * std::numbers::pi / 180;
  const double x = std::cos(mid), y = std::sin(mid);
  EXPECT_TRUE(on_boundary_curve({c}, x, y, 1e-4));
  EXPECT_TRUE(on_boundary_curve({c}, x, y - 3.8e-3, 1e-4));  // (the chord itself)
  EXPECT_FALSE(on_boundary_curve({c}, x, y + 0.05, 1e-4));
  EXPECT_FALSE(on_boundary_curve({c}, x, y - 0.05, 1e-4));
  EXPECT_FALSE(on_boundary_curve({c}, 1.5, 0.0, 1e-4));  // outside the curve's x range
}

// boundary_offset_along on a line whose test function is undefined near the start, as a coarser
// level's period-doubling test is at points of a flip lobe's finest curve (its critical pair not
// yet split on the real axis there): g = s - 3e-4, defined only for s >= 2e-4. The root is found
// from the nearest defined point, to the tolerance (the secant is exact on a line: 1e-15 here is
// rounding of s ~ 3e-4); without that search the offset was NaN.
TEST(Boundary, AnOffsetIsFoundFromTheNearestPointWhereTheTestFunctionIsDefined) {
  const auto g = [](double /*x*/, double y) {
    BoundarySample s;
    s.defined = y >= 2e-4;
    s.value = y - 3e-4;
    return s;
  };
  EXPECT_NEAR(boundary_offset_along(g, 0, 0, 0, 1, 1e-6, 1e-12), 3e-4, 1e-15);
  // On the other side too (the line's direction reversed), and from a guess where g is undefined.
  EXPECT_NEAR(boundary_offset_along(g, 0, 0, 0, -1, 1e-6, 1e-12), -3e-4, 1e-15);
  EXPECT_NEAR(boundary_offset_along(g, 0, 0, 0, 1, 1e-6, 1e-12, 1e-4), 3e-4, 1e-15);
  // Undefined within the search's reach (4e-3) on both sides: NaN, not a root made up.
  const auto far = [](double /*x*/, double y) {
    BoundarySample s;
    s.defined = std::abs(y) >= 1e-2;
    s.value = y - 2e-2;
    return s;
  };
  EXPECT_TRUE(std::isnan(boundary_offset_along(far, 0, 0, 0, 1, 1e-6, 1e-12)));
}

// The root nearest the point, the guess only the secant's second point: g = (s - 1e-3)(s - 0.5)
// has roots 1e-3 and 0.5; from 0 the secant finds 1e-3 with or without the guess 0.49 (a
// neighbour's offset to another part of the coarser curve is not carried on). Where g is
// undefined at the point (here below 0.2), from the guess: the root nearest it; without one, NaN
// (nothing defined within the search's reach). A secant step into where g is undefined (s > 0.6
// here) is halved back toward the last defined point.
TEST(Boundary, AnOffsetIsTheRootNearestThePointAndStartsFromTheGuessWhereThePointIsUndefined) {
  const auto g = [](double /*x*/, double y) {
    BoundarySample s;
    s.defined = y <= 0.6;
    s.value = (y - 1e-3) * (y - 0.5);
    return s;
  };
  EXPECT_NEAR(boundary_offset_along(g, 0, 0, 0, 1, 1e-6, 1e-13), 1e-3, 1e-12);
  EXPECT_NEAR(boundary_offset_along(g, 0, 0, 0, 1, 1e-6, 1e-13, 0.49), 1e-3, 1e-12);
  const auto undefined_at_the_point = [](double /*x*/, double y) {
    BoundarySample s;
    s.defined = y >= 0.2;
    s.value = (y - 0.5) * (y - 0.9);
    return s;
  };
  EXPECT_NEAR(boundary_offset_along(undefined_at_the_point, 0, 0, 0, 1, 1e-6, 1e-13, 0.85), 0.9, 1e-12);
  EXPECT_NEAR(boundary_offset_along(undefined_at_the_point, 0, 0, 0, 1, 1e-6, 1e-13, 0.45), 0.5, 1e-12);
  EXPECT_TRUE(std::isnan(boundary_offset_along(undefined_at_the_point, 0, 0, 0, 1, 1e-6, 1e-13)));
  // From 0 and 0.3 the first secant step overshoots far past 0.6 (g is nearly flat there relative
  // to its value): it is halved back and still ends on 0.5.
  const auto steep = [](double /*x*/, double y) {
    BoundarySample s;
    s.defined = y <= 0.6;
    s.value = std::exp(40 * (y - 0.5)) - 1;
    return s;
  };
  EXPECT_NEAR(boundary_offset_along(steep, 0, 0, 0, 1, 1e-6, 1e-13, 0.3), 0.5, 1e-12);
}

// A period-doubling curve ends where a second real multiplier reaches -1 (a 1:2 resonance: past
// it that multiplier is outside the circle and the curve bounds no stable region): the circle
// again, its second multiplier mu_2 = -1 - (v - 0.6) / 2, which crosses -1 where v = 0.6 on the
// upper half (u = 0.8). Located on the curve by the bracket along the chord, closed to the
// tolerance (1e-10 of the ranges): v to ~1e-9 as in the test above; it is the curve's last point.
TEST(Boundary, APeriodDoublingCurveEndsAtThe12ResonanceWhereASecondMultiplierReachesMinusOne) {
  const auto g = [](double u, double v) {
    BoundarySample s = circle(u, v);
    s.angle = std::numbers::pi;
    s.other_type = BifurcationType::period_doubling;
    const double mu2 = -1 - (v - 0.6) / 2;
    s.second_gap = std::abs(mu2 + 1);
    s.second_side = std::abs(mu2) - 1;
    return s;
  };
  BoundaryOptions o;
  o.x_from = 0.6, o.x_to = 1.5, o.y_from = -1.2, o.y_to = 1.2;
  const BoundaryCurve c = trace_boundary(g, -0.8, o);
  EXPECT_EQ(c.end, BoundaryEnd::codim2) << c.note;
  ASSERT_EQ(c.codim2.size(), 1u);
  EXPECT_EQ(c.codim2[0].kind, Codim2Kind::resonance_1_2);
  EXPECT_EQ(to_string(c.codim2[0]), "1:2 resonance");
  EXPECT_NEAR(c.codim2[0].y, 0.6, 1e-9);
  EXPECT_NEAR(c.codim2[0].x, 0.8, 2e-9);
  EXPECT_EQ(c.points.back().x, c.codim2[0].x);
  EXPECT_EQ(c.points.back().y, c.codim2[0].y);
  // Where the second multiplier stays away from -1 (0.2 from it at the closest), the curve goes on.
  const auto apart = [](double u, double v) {
    BoundarySample s = circle(u, v);
    s.angle = std::numbers::pi;
    s.other_type = BifurcationType::period_doubling;
    s.second_gap = 0.2 + std::abs(v - 0.6);
    s.second_side = -s.second_gap;
    return s;
  };
  EXPECT_EQ(trace_boundary(apart, -0.8, o).end, BoundaryEnd::from);
}

// A line that misses the coarser curve (its lobe's tip narrower): g has a maximum below 0 on it,
// and the secant wanders around that maximum. It stops after 14 steps without a sign change
// (16 evaluations with the two starting ones), not after the 20 steps a crossed search may take.
TEST(Boundary, AnOffsetSearchThatNeverSeesTheSignChangeStopsEarly) {
  int evaluations = 0;
  const auto g = [&evaluations](double /*x*/, double y) {
    ++evaluations;
    BoundarySample s;
    s.defined = true;
    s.value = -(y - 1e-3) * (y - 1e-3) - 1e-4;
    return s;
  };
  EXPECT_TRUE(std::isnan(boundary_offset_along(g, 0, 0, 0, 1, 1e-6, 1e-13)));
  EXPECT_LE(evaluations, 16);
}

// boundary_point_study on levels whose curves are v = C / N^2 (order 2 exactly, the limit v = 0),
// the coarsest (N = 100) nowhere defined, as a narrower coarser lobe's tip: from N = 200 and the
// curve's own 400 alone there is no estimate; with the refinement's level N = 800 the
// extrapolation from 200, 400, 800 lands on v = 0 (exact in h^2: to the secant's 1e-13 of the
// offsets, amplified by the tableau's weights, 1e-12).
namespace {
// The level N of the family v = C / N^2 below, undefined at N <= `missing` (a narrower lobe).
constexpr double kC = 40.0;
BoundaryFunction exact_h2_level(int N, int missing) {
  return [N, missing](double /*u*/, double v) {
    BoundarySample s;
    s.defined = N > missing;
    s.value = v - kC / (double(N) * N);
    return s;
  };
}
// The curve at N = 400 (three points on v = C / 400^2), and a location tolerance far below its
// offsets to the other levels.
BoundaryCurve exact_h2_curve() {
  BoundaryCurve curve;
  for (int k = 0; k < 3; ++k) curve.points.push_back({0.1 * k, kC / 160000.0, NAN, 0});
  return curve;
}
BoundaryOptions fine_scale() {
  BoundaryOptions scale;
  scale.tolerance = 1e-13;
  return scale;
}
}  // namespace

TEST(Boundary, APointWhoseCoarsestLevelIsMissingIsExtrapolatedWithTheFinerLevel) {
  constexpr double C = kC;
  const auto level = [](int N) { return exact_h2_level(N, 100); };
  const BoundaryCurve curve = exact_h2_curve();
  const BoundaryOptions scale = fine_scale();
  const std::vector<BoundaryFunction> coarser = {level(100), level(200)};
  const std::vector<int> Ns = {100, 200, 400};
  const BoundaryPointStudy without = boundary_point_study(curve, 1, coarser, Ns, scale, RichardsonOptions{});
  EXPECT_TRUE(std::isnan(without.y_error_estimate));
  EXPECT_TRUE(without.extrapolated_from.empty());
  const std::vector<BoundaryFunction> finer = {level(800), level(1600)};
  const BoundaryPointStudy with =
      boundary_point_study(curve, 1, coarser, Ns, scale, RichardsonOptions{}, nullptr, finer, {800, 1600});
  EXPECT_EQ(with.extrapolated_from, (std::vector<int>{200, 400, 800}));
  EXPECT_EQ(with.levels, (std::vector<int>{100, 200, 400, 800}));
  EXPECT_NEAR(with.y_extrapolated, 0.0, 1e-12);
  // Three levels: the bar is the correction the h^2 column made at the finest level (the h^4
  // column, which would show this one exact, cannot be checked): (C / 400^2 - C / 800^2) / 3.
  EXPECT_NEAR(with.y_error_estimate, (C / 160000.0 - C / 640000.0) / 3, 1e-12);
  EXPECT_NEAR(with.y_by_N[3], C / 640000.0, 1e-13);
}

// As above, with N = 200 missing too (a flip lobe's tip where even N = 200 has no flip lobe on the
// normal): 800 with 400 alone is two levels, whose estimate cannot be compared with the missing
// N = 200's offset, so the second refinement's 1600 is added, and 400, 800, 1600 land on v = 0
// with the bar of their h^2 column's correction, (C / 800^2 - C / 1600^2) / 3.
TEST(Boundary, APointWhoseTwoCoarsestLevelsAreMissingIsExtrapolatedWithTwoFinerLevels) {
  constexpr double C = kC;
  const auto level = [](int N) { return exact_h2_level(N, 200); };
  const BoundaryCurve curve = exact_h2_curve();
  const BoundaryOptions scale = fine_scale();
  const std::vector<BoundaryFunction> coarser = {level(100), level(200)}, finer = {level(800), level(1600)};
  const BoundaryPointStudy once =
      boundary_point_study(curve, 1, coarser, {100, 200, 400}, scale, RichardsonOptions{}, nullptr, {finer[0]}, {800});
  EXPECT_NE(once.extrapolated_from, (std::vector<int>{400, 800, 1600}));
  const BoundaryPointStudy twice =
      boundary_point_study(curve, 1, coarser, {100, 200, 400}, scale, RichardsonOptions{}, nullptr, finer, {800, 1600});
  EXPECT_EQ(twice.extrapolated_from, (std::vector<int>{400, 800, 1600}));
  EXPECT_EQ(twice.levels, (std::vector<int>{100, 200, 400, 800, 1600}));
  EXPECT_NEAR(twice.y_extrapolated, 0.0, 1e-12);
  EXPECT_NEAR(twice.y_error_estimate, (C / 640000.0 - C / 2560000.0) / 3, 1e-12);
}
