// A step that is not finite is found and reported with the points where it evaluated the model
// (NonFiniteStep, StroboscopicMap::throw_first_non_finite_step): for a derivative that becomes
// infinite at a known time, for a right-hand side that is NaN from the first step, through the
// analyses that use the step maps (the orbit's monodromy, Lyapunov), and no report for a finite
// model. The expected steps and points follow from the models' definitions, not from the code.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "delayspec/model_analyses.hpp"
#include "text_support.hpp"
#include "delayspec/model_analyses_continuation.hpp"

namespace {

using namespace delayspec;

using delayspec::testing::contains;

// What the two scalar test models share: y' = -y + g(t, y(t - 1)), T = tau = 1, no switching.
struct ScalarUnitDelay {
  static constexpr int d = 1;
  static constexpr bool has_switching = false;
  static constexpr bool affine_in_state = true;
  using V = Vec<1>;
  using M = Mat<1>;
  double tau() const { return 1; }
  double period() const { return 1; }
  M A(int, double, const V&, const V&) const { return M(-1.0); }
  double H(const V&) const { return 1; }
  V grad_H(const V&) const { return V::Zero(); }
};

// y' = -y + 0.5 y(t - 1), whose derivative by the delayed state is declared infinite from
// t = infinite_from on (as x^(1/3)'s is at x = 0): the step map of the first step whose right
// end t1 reaches infinite_from is not finite, and every earlier one is. The state never is (f
// and A are finite). With infinite_from > 1, finite everywhere.
struct DerivativeInfiniteFrom : ScalarUnitDelay {
  static constexpr bool is_linear = true;
  double infinite_from = 0.25;
  V f(int, double, const V& y, const V& w) const { return V(-y[0] + 0.5 * w[0]); }
  M B(int, double t, const V&, const V&) const {
    return M(t >= infinite_from ? std::numeric_limits<double>::infinity() : 0.5);
  }
  V initial_state() const { return V(1.0); }
};

// y' = -y + sqrt(y(t - 1)) from the history y = -1: f is NaN at the first step's left end.
struct SqrtOfNegativeHistory : ScalarUnitDelay {
  static constexpr bool is_linear = false;
  V f(int, double, const V& y, const V& w) const { return V(-y[0] + std::sqrt(w[0])); }
  M B(int, double, const V&, const V& w) const { return M(0.5 / std::sqrt(w[0])); }
  V initial_state() const { return V(-1.0); }
};

// N = 10 steps per delay: h = 0.1, and the first step whose right end reaches 0.25 is the third,
// from t = 0.2 to 0.3 (t = l h with integer l: exact up to one rounding, hence the 1e-15).
constexpr int kN = 10;

void expect_third_step(const NonFiniteStep& e) {
  EXPECT_TRUE(contains(e.what(), "map 1, step 3")) << e.what();
  EXPECT_TRUE(contains(e.what(), "derivative (step map)")) << e.what();
  ASSERT_EQ(e.points().size(), 2u);
  EXPECT_NEAR(e.points()[0].t, 0.2, 1e-15);
  EXPECT_NEAR(e.points()[1].t, 0.3, 1e-15);
  // The zero orbit of the linear model (monodromy) or a finite state (Lyapunov): finite points.
  for (const ModelPoint& p : e.points()) {
    ASSERT_EQ(p.y.size(), 1u);
    ASSERT_EQ(p.y_tau.size(), 1u);
    EXPECT_TRUE(std::isfinite(p.y[0]) && std::isfinite(p.y_tau[0]));
  }
}

TEST(NonFiniteStep, TheMapFindsTheFirstStepWhoseDerivativeIsNotFinite) {
  const DerivativeInfiniteFrom model;
  const StroboscopicMap<DerivativeInfiniteFrom> map(TrapezoidStepper<DerivativeInfiniteFrom>(model, {}),
                                                    make_grid(1, 1, kN, 1));
  try {
    map.throw_first_non_finite_step(map.constant_history(model.initial_state()), 2, "test");
    FAIL() << "no step reported";
  } catch (const NonFiniteStep& e) {
    EXPECT_EQ(std::string(e.what()).rfind("test (", 0), 0u) << e.what();
    expect_third_step(e);
    // The constant history 1 is the delayed value of the first map's steps.
    EXPECT_EQ(e.points()[0].y_tau[0], 1.0);
  }
}

TEST(NonFiniteStep, AFiniteModelIsNotReported) {
  DerivativeInfiniteFrom model;
  model.infinite_from = 2;  // after the maps looked at: t < 1 in every map
  const StroboscopicMap<DerivativeInfiniteFrom> map(TrapezoidStepper<DerivativeInfiniteFrom>(model, {}),
                                                    make_grid(1, 1, kN, 1));
  EXPECT_NO_THROW(map.throw_first_non_finite_step(map.constant_history(model.initial_state()), 5, "test"));
}

TEST(NonFiniteStep, TheOrbitsMonodromyIsNotReturnedWithAnInfiniteStepMap) {
  const ModelAnalysesFor<DerivativeInfiniteFrom> analyses{DerivativeInfiniteFrom{}};
  MapSettings map;
  map.N = kN;
  try {
    analyses.linearised_orbit(map, OrbitSettings{}, OrbitRequest{});
    FAIL() << "a monodromy with infinite entries was returned";
  } catch (const NonFiniteStep& e) {
    expect_third_step(e);
    EXPECT_EQ(e.points()[0].y[0], 0.0);  // the zero orbit of a linear model
  }
}

TEST(NonFiniteStep, LyapunovNamesTheStepBehindANonFiniteTangentBlock) {
  const ModelAnalysesFor<DerivativeInfiniteFrom> analyses{DerivativeInfiniteFrom{}};
  MapSettings map;
  map.N = kN;
  LyapunovOptions options;
  options.exponents = 1;
  options.transient = 0;
  options.periods = 20;
  options.batches = 2;
  try {
    analyses.lyapunov(map, options);
    FAIL() << "Lyapunov exponents from an infinite tangent block";
  } catch (const NonFiniteStep& e) {
    EXPECT_TRUE(contains(e.what(), "Lyapunov QR")) << e.what();
    expect_third_step(e);
  }
}

TEST(NonFiniteStep, AStateThatIsNotFiniteIsReportedWithTheFirstPointsItsStepEvaluated) {
  const SqrtOfNegativeHistory model;
  const StroboscopicMap<SqrtOfNegativeHistory> map(TrapezoidStepper<SqrtOfNegativeHistory>(model, {}),
                                                   make_grid(1, 1, kN, 1));
  try {
    map.apply(map.constant_history(model.initial_state()));
    FAIL() << "a NaN state was returned";
  } catch (const NonFiniteStep& e) {
    EXPECT_TRUE(contains(e.what(), "trapezoid step at t = 0,")) << e.what();
    ASSERT_EQ(e.points().size(), 2u);
    // The left end (t = 0, y = -1, y(t - 1) = -1) and the right end's first Newton point
    // (t = h, from the same state, the history's -1 delayed).
    EXPECT_EQ(e.points()[0].t, 0.0);
    EXPECT_EQ(e.points()[0].y[0], -1.0);
    EXPECT_EQ(e.points()[0].y_tau[0], -1.0);
    EXPECT_NEAR(e.points()[1].t, 0.1, 1e-16);
    EXPECT_EQ(e.points()[1].y[0], -1.0);
    EXPECT_EQ(e.points()[1].y_tau[0], -1.0);
  }
}

}  // namespace
