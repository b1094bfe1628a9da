// Named hard cases of event location (issue 3): each gives a finite step map that passes a
// finite-difference check. Where the discrete step is only one-sided differentiable (an event
// leaving the step through one of its ends, the onset of grazing: see event_step.hpp), the
// check uses one-sided differences from the side the step map describes.
#include <gtest/gtest.h>

#include "event_fd_support.hpp"

using namespace delayspec;
using namespace delayspec::testing;

namespace {

// One-sided second-order differences err by delta^2/3 |y'''| (plus rounding 2 eps |y| / delta):
// with |y'''| <~ 1e4 near an impact of speed ~0.05 (test_events.cpp) and delta = 1e-6, ~3e-9.
constexpr double kOneSidedDelta = 1e-6;
constexpr double kOneSidedTolerance = 1e-6;
constexpr int kForward[6] = {1, 1, 1, 1, 1, 1};

// The orbit's step 24 (N = 100, events on, literal data): starts below the obstacle, rising
// with speed 0.11; its free-flight sub-step reaches x = e = 1.26 within the step.
StepInput rising_step() {
  return {1.8802549547669585, 0.07834395644862325, V2(1.2538623987816964, 0.10961567106070286),
          V2(1.2538623986659863, 0.10961567102965634), V2(1.2599683894228073, 0.046260826242349999)};
}

// x of the free-flight (region 2) sub-step of length s from the step's start.
double free_flight_x(const ImpactModel& model, const StepInput& in, double s) {
  const TrapezoidStepper<ImpactModel> stepper(model);
  const V2 ws = (1 - s / in.h) * in.w0 + (s / in.h) * in.w1;
  return stepper.sub_step(in.t, s, in.u0, in.w0, ws, 2, 2).z1[0];
}

void expect_finite(const StepJacobian& J) { EXPECT_TRUE(J.allFinite()) << J; }

// Highest point of the free-flight sub-step minus e: the penetration a step would see.
double penetration(const ImpactModel& model, const StepInput& in) {
  const ScalarSearchResult top = bounded_minimum([&](double s) { return -free_flight_x(model, in, s); }, 0, in.h);
  return -top.g - model.parameters().e;
}

// Per input, the direction that lowers the penetration (the no-contact side).
void sides_lowering_penetration(const ImpactModel& model, const StepInput& in, int (&sides)[6]) {
  for (int c = 0; c < 6; ++c) {
    StepInput p = in;
    input_component(p, c) += 1e-6;
    sides[c] = penetration(model, p) > penetration(model, in) ? -1 : 1;
  }
}

}  // namespace

TEST(EventHardCases, CrossingOneTrillionthOfAStepAfterItsStart) {
  ImpactParameters params = paper_orbit_parameters();
  const StepInput in = rising_step();
  params.e = free_flight_x(ImpactModel(params), in, 1e-12 * in.h);  // H(z(s)) = 0 at s = 1e-12 h
  const ImpactModel model(params);
  ASSERT_LT(model.H(in.u0), 0);
  const TrapezoidStepper<ImpactModel> stepper(model);
  StepEvents events;
  const StepJacobian J = step_jacobian(stepper, in, &events);
  ASSERT_EQ(events.count, 1);
  EXPECT_LE(events.offset[0], 1e-11 * in.h);  // e is rounded to 16 digits: the offset to ~10 %
  expect_finite(J);
  // Raising x(0) by more than 1e-14 moves the event out through the step's start: differences
  // lower x; every other input keeps the event inside.
  const int sides[6] = {-1, 1, 1, 1, 1, 1};
  EXPECT_LE(relative_error(one_sided_differences(stepper, in, kOneSidedDelta, sides), J), kOneSidedTolerance);
}

TEST(EventHardCases, CrossingOneTrillionthOfAStepBeforeItsEnd) {
  ImpactParameters params = paper_orbit_parameters();
  const StepInput in = rising_step();
  params.e = free_flight_x(ImpactModel(params), in, (1 - 1e-12) * in.h);
  const ImpactModel model(params);
  const TrapezoidStepper<ImpactModel> stepper(model);
  StepEvents events;
  const StepJacobian J = step_jacobian(stepper, in, &events);
  ASSERT_EQ(events.count, 1);
  EXPECT_GE(events.offset[0], (1 - 1e-11) * in.h);
  expect_finite(J);
  // Increasing any input (higher x, faster rise, larger delayed speed through k) makes the
  // crossing earlier: forward differences keep it inside the step.
  EXPECT_LE(relative_error(one_sided_differences(stepper, in, kOneSidedDelta, kForward), J), kOneSidedTolerance);
}

TEST(EventHardCases, HExactlyZeroAtAGridPointRising) {
  ImpactParameters params = paper_orbit_parameters();
  const StepInput in = rising_step();
  params.e = in.u0[0];  // H(u0) = 0 exactly: region 2 by convention, rising into region 1
  const ImpactModel model(params);
  const TrapezoidStepper<ImpactModel> stepper(model);
  StepEvents events;
  const StepJacobian J = step_jacobian(stepper, in, &events);
  ASSERT_EQ(events.count, 1);
  EXPECT_EQ(events.offset[0], 0.0);
  EXPECT_EQ(events.new_region[0], 1);
  expect_finite(J);
  // The step map is the limit from the H < 0 side: lower x(0); the other inputs leave H(u0) = 0.
  const int sides[6] = {-1, 1, 1, 1, 1, 1};
  EXPECT_LE(relative_error(one_sided_differences(stepper, in, kOneSidedDelta, sides), J), kOneSidedTolerance);
  // And it is not the derivative from the other side (the one-sided derivatives differ by
  // O(h^2 beta) ~ 1e-2 here): the check above can tell the sides apart.
  const int other[6] = {1, 1, 1, 1, 1, 1};
  EXPECT_GT(relative_error(one_sided_differences(stepper, in, kOneSidedDelta, other), J), 1e3 * kOneSidedTolerance);
}

TEST(EventHardCases, HExactlyZeroAtAGridPointFalling) {
  ImpactParameters params = paper_orbit_parameters();
  StepInput in = rising_step();
  in.u0[1] = -in.u0[1];  // falling: stays in region 2, no event
  params.e = in.u0[0];
  const ImpactModel model(params);
  const TrapezoidStepper<ImpactModel> stepper(model);
  StepEvents events;
  const StepJacobian J = step_jacobian(stepper, in, &events);
  EXPECT_EQ(events.count, 0);
  expect_finite(J);
  const int sides[6] = {-1, 1, 1, 1, 1, 1};
  EXPECT_LE(relative_error(one_sided_differences(stepper, in, kOneSidedDelta, sides), J), kOneSidedTolerance);
}

// A tangential touch: the highest point of the step is exactly on H = 0, or 1e-14 beyond it
// (below the grazing threshold of a few hundred ulps: no split, a contact that shallow changes
// the step by ~beta p^1.5 ~ 1e-20). The step map is the plain one, the derivative from the
// no-contact side.
void expect_touch_is_plain_step(double depth) {
  const GrazingCase g = grazing_case(depth);
  const ImpactModel model(g.parameters);
  const TrapezoidStepper<ImpactModel> stepper(model);
  EXPECT_NEAR(penetration(model, g.input), depth, 1e-15);
  StepEvents events;
  const StepJacobian J = step_jacobian(stepper, g.input, &events);
  EXPECT_EQ(events.count, 0);
  expect_finite(J);
  int sides[6];
  sides_lowering_penetration(model, g.input, sides);
  EXPECT_LE(relative_error(one_sided_differences(stepper, g.input, kOneSidedDelta, sides), J), kOneSidedTolerance);
}

TEST(EventHardCases, TangentialTouchExactlyOnTheSurface) { expect_touch_is_plain_step(0); }

TEST(EventHardCases, TangentialTouchOneHundredthOfAnUlpDeep) { expect_touch_is_plain_step(1e-14); }

TEST(EventHardCases, GrazingPenetrationOneTenBillionth) {
  const GrazingCase g = grazing_case(1e-10);
  const ImpactModel model(g.parameters);
  const TrapezoidStepper<ImpactModel> consistent(model);
  StepOptions frozen_options;
  frozen_options.jacobian = JacobianMode::frozen;
  const TrapezoidStepper<ImpactModel> frozen(model, frozen_options);
  StepEvents events;
  const StepJacobian J = step_jacobian(consistent, g.input, &events);
  ASSERT_EQ(events.count, 2);
  expect_finite(J);
  // With the whole contact (c = sqrt(8 p / |x''|) ~ 3e-5) inside one step, the discrete step
  // depends on c linearly (the trapezoid's O(h^3) local error moves with each split point, and
  // the two moves do not cancel), so its derivative grows like h^2 / c ~ p^(-1/2): the exact
  // derivative of the discrete map is large here, and the step varies on the scale of p itself.
  // Differences therefore need delta << p: delta = 1e-12 keeps both points grazing (an input
  // moves p by at most ~delta). Central error ~ delta^2 / (6 p^2) ~ 2e-5 relative, rounding
  // 2 eps |y| / (delta |J|) ~ 1e-6: tolerance 2e-4.
  const StepJacobian F = central_differences(consistent, g.input, 1e-12);
  EXPECT_LE(relative_error(F, J), 2e-4);
  // The growth itself: a hundred times shallower, ten times larger (within 30 %: the p^(-1/2)
  // term dominates both, plus an O(1) part).
  const GrazingCase deeper = grazing_case(1e-8);
  const TrapezoidStepper<ImpactModel> deeper_stepper{ImpactModel(deeper.parameters)};
  const double growth =
      J.lpNorm<Eigen::Infinity>() / step_jacobian(deeper_stepper, deeper.input).lpNorm<Eigen::Infinity>();
  EXPECT_NEAR(growth, 10, 3);
  // The frozen map has no such term: wrong by O(1).
  EXPECT_GT(relative_error(F, step_jacobian(frozen, g.input)), 0.5);
}

TEST(EventHardCases, EventsInConsecutiveSteps) {
  // The orbit's steps 25 (entry at 0.16 h) and 26 (exit at 0.29 h) at N = 100, literal data.
  const ImpactModel model(paper_orbit_parameters());
  const TrapezoidStepper<ImpactModel> stepper(model);
  const double h = 0.07834395644862325;
  const StepInput step25{1.9585989112155817, h, V2(1.2599683895405265, 0.046260826262594042),
                         V2(1.2599683894228073, 0.046260826242349999), V2(1.2610590616842017, -0.018427987652669953)};
  StepEvents events;
  StepMap<2> map25;
  const V2 u26 = stepper.step(step25.t, h, step25.u0, step25.w0, step25.w1, map25, &events);
  ASSERT_EQ(events.count, 1);
  EXPECT_EQ(events.new_region[0], 1);
  const StepInput step26{step25.t + h, h, u26, V2(1.2610590616842017, -0.018427987652669953),
                         V2(1.2570980281905109, -0.082383181615476392)};
  const StepJacobian J26 = step_jacobian(stepper, step26, &events);
  ASSERT_EQ(events.count, 1);
  EXPECT_EQ(events.new_region[0], 2);
  EXPECT_LE(relative_error(central_differences(stepper, step25, kOneSidedDelta), as_matrix(map25)), kOneSidedTolerance);
  EXPECT_LE(relative_error(central_differences(stepper, step26, kOneSidedDelta), J26), kOneSidedTolerance);
  // The two steps composed, wrt u0 of step 25 (the delayed values are history, fixed):
  // d u(t + 2h) / d u(t) = P26 P25.
  Mat<2> composed_fd;
  for (int c = 0; c < 2; ++c) {
    StepInput p = step25, m = step25;
    p.u0[c] += kOneSidedDelta;
    m.u0[c] -= kOneSidedDelta;
    StepInput p26 = step26, m26 = step26;
    p26.u0 = step_value(stepper, p);
    m26.u0 = step_value(stepper, m);
    composed_fd.col(c) = (step_value(stepper, p26) - step_value(stepper, m26)) / (2 * kOneSidedDelta);
  }
  const Mat<2> composed = J26.leftCols<2>() * map25.P;
  EXPECT_LE((composed_fd - composed).lpNorm<Eigen::Infinity>(), kOneSidedTolerance * composed.lpNorm<Eigen::Infinity>());
}

TEST(EventHardCases, EventInTheLastStepOfAPeriod) {
  // From the constant history (x0, v0) of the default scene, N = 40, choose the obstacle e
  // between x at the start and end of the map's last step (scanning candidates: the trajectory
  // before the last step depends on e only where x > e), so that the last step has an event;
  // then the whole stroboscopic map's differences must match the monodromy.
  const int N = 40;
  ImpactParameters params = paper_orbit_parameters();
  bool found = false;
  for (int i = 0; i <= 400 && !found; ++i) {
    params.e = -1.5 + 3.0 * i / 400;
    const ImpactModel model(params);
    const TrapezoidStepper<ImpactModel> stepper(model);
    const StroboscopicMap<ImpactModel> map(stepper, make_grid(model.tau(), model.period(), N));
    const Eigen::VectorXd U = map.constant_history(model.initial_state());
    const std::vector<StepInput> inputs = step_inputs(map, U);
    StepEvents events;
    step_value(stepper, inputs.back(), &events);
    if (events.count == 0) continue;
    found = true;
    const Monodromy<2> M = map.monodromy(U);
    const Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(map.dimension(), -1, 1);
    // 40 steps with events: the per-step FD bound, amplified by a product of step maps of
    // norm ~1: 1e-6.
    const Eigen::VectorXd fd = (map.apply(U + kOneSidedDelta * v) - map.apply(U - kOneSidedDelta * v)) / (2 * kOneSidedDelta);
    Eigen::VectorXd Mv;
    M.apply(v, Mv);
    EXPECT_LE((fd - Mv).lpNorm<Eigen::Infinity>(), kOneSidedTolerance * Mv.lpNorm<Eigen::Infinity>()) << "e = " << params.e;
  }
  EXPECT_TRUE(found);
}

TEST(EventHardCases, StiffContactBetaTenThousand) {
  // beta = 1e4: contact frequency 100, h beta^(1/2) ~ 8: the trapezoid stays stable (A-stable)
  // and the event location does not care. A crossing step and a grazing step, both checked.
  ImpactParameters params = paper_orbit_parameters();
  params.beta = 1e4;
  const StepInput in = rising_step();
  params.e = free_flight_x(ImpactModel(params), in, 0.5 * in.h);  // entry at mid-step
  const ImpactModel model(params);
  const TrapezoidStepper<ImpactModel> stepper(model);
  StepEvents events;
  const StepJacobian J = step_jacobian(stepper, in, &events);
  ASSERT_GE(events.count, 1);
  expect_finite(J);
  // Entries of the map grow with beta h ~ 1e3; the FD error scales alike (relative check).
  EXPECT_LE(relative_error(central_differences(stepper, in, kOneSidedDelta), J), kOneSidedTolerance);

  const GrazingCase g = grazing_case(1e-4, 0.25, 1e4);
  const ImpactModel graze_model(g.parameters);
  const TrapezoidStepper<ImpactModel> graze_stepper(graze_model);
  const StepJacobian Jg = step_jacobian(graze_stepper, g.input, &events);
  ASSERT_EQ(events.count, 2);
  expect_finite(Jg);
  EXPECT_LE(relative_error(central_differences(graze_stepper, g.input, 1e-7), Jg), kOneSidedTolerance);
}
