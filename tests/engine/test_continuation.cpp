// Continuation of periodic orbits (continuation.hpp): every located bifurcation is checked
// against a value the code did not produce (an exact characteristic root, an exact equilibrium
// branch, the closed-form amplitude of a forced linear oscillator).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "delayspec/continuation.hpp"
#include "delayspec/detail/bifurcation_locator.hpp"
#include "delayspec/model_impact.hpp"
#include "delayspec/model_linear.hpp"
#include "delayspec/model_mathieu.hpp"
#include "impact_gap_branch.hpp"
#include "saddle_node_model.hpp"
#include "test_support.hpp"

namespace delayspec {
namespace {

using std::numbers::pi;
namespace branch_detail = continuation_detail;
using testing::SaddleNodeDelayModel;

// x' = -x + b x(t - tau), tau = 2 pi / (3 sqrt 3): roots +-i sqrt 3 at b = -2 (i sqrt 3 = -1 - 2
// exp(-i 2 pi / 3)), stable for -2 < b < 0 near there; multipliers per period T = tau
// exp(+-i sqrt 3 tau) = exp(+-2 pi i / 3).
const double kLinearTau = 2 * pi / (3 * std::sqrt(3.0));

ContinuationResult linear_branch(int N, double tolerance) {
  ContinuationOptions o;
  o.from = -1.5;
  o.to = -2.5;
  o.N = N;
  o.tolerance = tolerance;
  auto model_at = [](double b) { return LinearModel({-1, b, kLinearTau, kLinearTau}); };
  return continue_orbit<LinearModel>(model_at, Eigen::VectorXd::Zero(N), o);
}

TEST(Continuation, HermiteMaximumOfKnownCubics) {
  // g(u) = u (1 - u) on [0, 1] (h = 1): max 1/4 at 1/2; slopes 1 and -1
  EXPECT_NEAR(branch_detail::hermite_maximum(0, 0, 1, -1, 1), 0.25, 1e-15);
  // monotone: the larger end
  EXPECT_DOUBLE_EQ(branch_detail::hermite_maximum(0, 1, 1, 1, 1), 1.0);
  // g(t) = sin(t) sampled at 1 and 2 (h = 1): the cubic's maximum is within h^4 / 384 of 1
  EXPECT_NEAR(branch_detail::hermite_maximum(std::sin(1.0), std::sin(2.0), std::cos(1.0), std::cos(2.0), 1.0), 1.0, 1.0 / 384);
}

TEST(Continuation, DetectionCountsSeparateCrossingsFromCollisions) {
  using C = std::complex<double>;
  auto counts = [](std::vector<C> m) { return branch_detail::unstable_counts(m); };
  // a real multiplier through +1: fold
  EXPECT_EQ(branch_detail::detected_changes(counts({C(0.9)}), counts({C(1.1)})),
            std::vector<BifurcationType>{BifurcationType::fold});
  // through -1: period doubling
  EXPECT_EQ(branch_detail::detected_changes(counts({C(-0.9)}), counts({C(-1.1)})),
            std::vector<BifurcationType>{BifurcationType::period_doubling});
  // a pair through the circle: Neimark-Sacker
  EXPECT_EQ(branch_detail::detected_changes(counts({C(0.5, 0.8), C(0.5, -0.8)}), counts({C(0.6, 0.9), C(0.6, -0.9)})),
            std::vector<BifurcationType>{BifurcationType::neimark_sacker});
  // two real multipliers > 1 colliding into a pair outside the circle: nothing crosses it
  EXPECT_TRUE(branch_detail::detected_changes(counts({C(1.5), C(1.4)}), counts({C(1.45, 0.1), C(1.45, -0.1)})).empty());
}

TEST(Continuation, NeimarkSackerOfLinearDdeAtExactBoundary) {
  // The discrete boundary b_N = -2 + c h^2 + O(h^4) (the trapezoid rule is symmetric);
  // located to 1e-13 in b (|mu| - 1 has slope O(1) in b, Krylov gives |mu| to ~1e-14).
  const std::vector<int> Ns = {100, 200, 400, 800};
  std::vector<std::vector<Bifurcation>> by_N;
  for (int N : Ns) {
    const ContinuationResult r = linear_branch(N, 1e-13);
    ASSERT_EQ(r.end, BranchEnd::to) << r.failure;
    ASSERT_EQ(r.bifurcations.size(), 1u) << "N = " << N;
    const Bifurcation& b = r.bifurcations[0];
    EXPECT_EQ(b.type, BifurcationType::neimark_sacker);
    EXPECT_LE(b.bracket, 1e-13) << b.note;
    // angle per period 2 pi / 3 up to the O(h^2) discretisation error (h = tau / N)
    const double h = kLinearTau / N;
    EXPECT_NEAR(b.angle, 2 * pi / 3, 5 * h * h) << "N = " << N;
    EXPECT_NEAR(b.parameter, -2, 5 * h * h) << "N = " << N;
    // the points on either side: stable before, one unstable pair after
    EXPECT_TRUE(r.points[b.after_point].stable());
    EXPECT_EQ(r.points[b.after_point + 1].unstable, 2);
    by_N.push_back(r.bifurcations);
  }
  // second order: successive differences shrink by 4
  const auto all = extrapolate_bifurcations(Ns, by_N, 1e-13);
  ASSERT_EQ(all.size(), 1u);
  EXPECT_NEAR(all[0].observed_order, 2, 0.05);
  // the extrapolated boundary is within its own error estimate of -2, and that is <= 1e-8
  EXPECT_LE(std::abs(all[0].extrapolated + 2), all[0].error_estimate) << all[0].note;
  EXPECT_LE(all[0].error_estimate, 1e-8) << all[0].note;
  // the default levels 200, 400, 800: honest too
  const auto three = extrapolate_bifurcations({200, 400, 800}, {by_N[1], by_N[2], by_N[3]}, 1e-13);
  ASSERT_EQ(three.size(), 1u);
  EXPECT_LE(std::abs(three[0].extrapolated + 2), three[0].error_estimate) << three[0].note;
}

TEST(Continuation, PassesTheFoldOfAnExactEquilibriumBranch) {
  ContinuationOptions o;
  o.from = 1;
  o.to = -1;  // never reached: the branch turns at p = 0 and comes back past p = 1
  o.N = 40;
  o.tolerance = 1e-12;
  auto model_at = [](double p) { return SaddleNodeDelayModel{p, 0.5}; };
  const ContinuationResult r = continue_orbit<SaddleNodeDelayModel>(model_at, Eigen::VectorXd::Constant(40, 1.0), o);
  ASSERT_EQ(r.end, BranchEnd::from) << r.failure;
  ASSERT_EQ(r.bifurcations.size(), 1u);
  const Bifurcation& fold = r.bifurcations[0];
  EXPECT_EQ(fold.type, BifurcationType::fold);
  EXPECT_NEAR(fold.parameter, 0, 1e-12);
  EXPECT_NEAR(fold.angle, 0, 1e-12);
  // on the branch: x = +sqrt(p) stable before the fold, x = -sqrt(p) with one multiplier > 1 after
  double lowest = INFINITY;
  for (const auto& pt : r.points) {
    lowest = std::min(lowest, pt.parameter);
    const bool upper = &pt - &r.points[0] <= fold.after_point;
    const double x = (upper ? 1 : -1) * std::sqrt(std::max(pt.parameter, 0.0));
    // the measure is the constant state itself; |F| <= 1e-12 leaves x accurate to 1e-12 / |f_x|
    EXPECT_NEAR(pt.measures.max[0], x, 1e-9) << "p = " << pt.parameter;
    EXPECT_EQ(pt.unstable, upper ? 0 : 1) << "p = " << pt.parameter;
  }
  EXPECT_GE(lowest, 0);  // the branch never goes past the turning point
  EXPECT_EQ(r.points.back().parameter, 1);
  // |F|_inf <= 1e-12 (1 + |x|) per step of h = 1 / 40 with |f_x| = 2.5: x to ~3e-11
  EXPECT_NEAR(r.points.back().measures.max[0], -1, 1e-10);
}

// The impact model at tau = T continued in the gap: it grazes at e = A (impact_gap_branch.hpp).
TEST(Continuation, GrazingOfImpactOrbitAtFreeAmplitude) {
  const ImpactParameters base;
  const double A = testing::free_amplitude(base);
  const std::vector<int> Ns = {100, 200, 400};
  std::vector<std::vector<Bifurcation>> by_N;
  for (int N : Ns) {
    ContinuationOptions o;
    o.from = 1.3;
    o.to = 1.2;
    o.N = N;
    o.tolerance = 1e-13;
    const testing::ImpactInGap model_at{base, 0.5};
    // the start: the free orbit (no contact at e = 1.3 > A), from the exact solution as a guess
    const double h = 2 * pi / base.omega / N;
    const Eigen::VectorXd guess = testing::free_orbit_sequence(base, N);
    const ContinuationResult r = continue_orbit<ImpactModel>(model_at, guess, o);
    ASSERT_EQ(r.end, BranchEnd::to) << r.failure;
    // the branch also loses stability in contact (a Neimark-Sacker point near e = 1.256 with k = 0.5);
    // the grazing point is the one known exactly
    std::vector<Bifurcation> grazing;
    for (const auto& b : r.bifurcations)
      if (b.type == BifurcationType::grazing) grazing.push_back(b);
    ASSERT_EQ(grazing.size(), 1u) << "N = " << N;
    EXPECT_NEAR(grazing[0].parameter, A, 10 * h * h);
    EXPECT_LE(grazing[0].bracket, 1e-13) << grazing[0].note;
    // no contact before, contact after
    EXPECT_EQ(r.points.front().measures.contact_time, 0);
    EXPECT_GT(r.points.back().measures.contact_time, 0);
    by_N.push_back(grazing);
  }
  const auto all = extrapolate_bifurcations(Ns, by_N, 1e-13);
  ASSERT_EQ(all.size(), 1u);
  EXPECT_NEAR(all[0].observed_order, 2, 0.1);
  EXPECT_LE(std::abs(all[0].extrapolated - A), all[0].error_estimate) << all[0].note;
}

// The delayed Mathieu equation (kappa = 0.1, delta = 2, eps = 1) loses stability near b = -1.41
// as b decreases through a real multiplier -1. Checked against the dense LAPACK spectrum of the
// same discretisation at the located b (a different eigensolver on the assembled matrix: the
// location is where that spectrum holds -1), and the order in N.
TEST(Continuation, PeriodDoublingOfDelayedMathieuAtMultiplierMinusOne) {
  const std::vector<int> Ns = {100, 200, 400};
  std::vector<std::vector<Bifurcation>> by_N;
  for (int N : Ns) {
    ContinuationOptions o;
    o.from = -1.3;
    o.to = -1.5;
    o.N = N;
    o.tolerance = 1e-12;
    auto model_at = [](double b) { return MathieuModel({0.1, 2, 1, b}); };
    const ContinuationResult r = continue_orbit<MathieuModel>(model_at, Eigen::VectorXd::Zero(2 * N), o);
    ASSERT_EQ(r.end, BranchEnd::to) << r.failure;
    ASSERT_EQ(r.bifurcations.size(), 1u) << "N = " << N;
    const Bifurcation& pd = r.bifurcations[0];
    EXPECT_EQ(pd.type, BifurcationType::period_doubling);
    EXPECT_NEAR(pd.angle, pi, 1e-12);
    // |mu + 1| <= tolerance |d mu / d b| (O(1)) + the eigensolvers' accuracy (~1e-12)
    const auto dense = testing::dense_multipliers(MathieuModel({0.1, 2, 1, pd.parameter}), N, 4);
    EXPECT_LE(testing::distance_to_nearest(dense, -1.0), 1e-9) << "N = " << N;
    by_N.push_back(r.bifurcations);
  }
  const auto all = extrapolate_bifurcations(Ns, by_N, 1e-12);
  ASSERT_EQ(all.size(), 1u);
  EXPECT_NEAR(all[0].observed_order, 2, 0.1);
}

TEST(Continuation, StepThatCannotBeReducedEndsTheBranchWithThePointReached) {
  // The model does not exist for p > 0.5 (BadInput from the factory): the branch from p = 0.1
  // towards 1 shrinks its step at the edge until it is below step_min.
  ContinuationOptions o;
  o.from = 0.1;
  o.to = 1;
  o.N = 20;
  auto model_at = [](double p) {
    if (p > 0.5) throw BadInput("`p = " + format_number(p) + "`: must be <= 0.5");
    return SaddleNodeDelayModel{p, 0.5};
  };
  const ContinuationResult r =
      continue_orbit<SaddleNodeDelayModel>(model_at, Eigen::VectorXd::Constant(20, std::sqrt(0.1)), o);
  EXPECT_EQ(r.end, BranchEnd::failure);
  ASSERT_GE(r.points.size(), 2u);
  EXPECT_LE(r.points.back().parameter, 0.5);
  // the branch went as far as the edge allows: beyond 0.4 (its steps are at most 0.09)
  EXPECT_GT(r.points.back().parameter, 0.4);
  EXPECT_NE(r.failure.find("step below continue_step_min"), std::string::npos) << r.failure;
  EXPECT_NE(r.failure.find("at parameter " + format_number(r.points.back().parameter)), std::string::npos) << r.failure;
  EXPECT_NE(r.failure.find("must be <= 0.5"), std::string::npos) << r.failure;
  for (const auto& pt : r.points) EXPECT_NEAR(pt.measures.max[0], std::sqrt(pt.parameter), 1e-9);
}

TEST(Continuation, BadInputAndFailures) {
  auto model_at = [](double b) { return LinearModel({-1, b, 1, 1}); };
  ContinuationOptions o;
  o.from = o.to = 1;
  EXPECT_THROW(continue_orbit<LinearModel>(model_at, Eigen::VectorXd::Zero(100), o), BadInput);
  o.to = 2;
  o.step_min = 1;
  o.step_max = 0.1;
  EXPECT_THROW(continue_orbit<LinearModel>(model_at, Eigen::VectorXd::Zero(100), o), BadInput);
  o.step_min = 0;
  o.step_max = 0;
  EXPECT_THROW(continue_orbit<LinearModel>(model_at, Eigen::VectorXd::Zero(7), o), BadInput);  // wrong size
  // Newton cannot start: the saddle-node has no equilibrium for p < 0
  ContinuationOptions s;
  s.from = -1;
  s.to = 1;
  s.N = 20;
  s.start_iterations = 20;
  auto saddle = [](double p) { return SaddleNodeDelayModel{p, 0.5}; };
  try {
    continue_orbit<SaddleNodeDelayModel>(saddle, Eigen::VectorXd::Constant(20, 1.0), s);
    FAIL() << "no equilibrium at p = -1, yet Newton converged";
  } catch (const NumericalFailure& e) {
    EXPECT_NE(std::string(e.what()).find("|F|_inf"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace delayspec
