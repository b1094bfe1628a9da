// Event steps (crossing and grazing inside a step): the consistent step map is the exact
// derivative of the discrete step, checked against central finite differences of the step and of
// the whole stroboscopic map on the paper's period-1 orbit with impacts; the frozen (paper's)
// Jacobian is not, near grazing.
#include <gtest/gtest.h>

#include <random>

#include "event_fd_support.hpp"

using namespace delayspec;
using namespace delayspec::testing;

namespace {

// FD step and tolerance for the step checks. The step is smooth in its inputs away from the
// degenerate points (event_step.hpp header); central differences err by delta^2/6 |y'''|. Near an
// impact the third derivative is dominated by the event time s(u) ~ H/v with impact speed
// v ~ 0.05 on this orbit: |s'''| ~ 1/v^3 ~ 1e4, times |f| ~ 1: delta = 1e-6 gives ~2e-9, plus
// rounding eps |y| / delta ~ 1e-10. 1e-6 relative (the bound) leaves a wide margin
// and is still 1e5 times smaller than the frozen Jacobian's error.
constexpr double kDelta = 1e-6;
constexpr double kTolerance = 1e-6;

// The period-1 orbit of events = on, consistent, one sub-step (N = 100), and a stepper with
// `options` whose steps are checked along it. (Other options have slightly different discrete
// orbits; at N = 100 some of them are not reached from this start, so all checks use this one.)
struct OrbitFixture {
  ImpactModel model;
  TrapezoidStepper<ImpactModel> stepper;
  StroboscopicMap<ImpactModel> map;
  PeriodicOrbit orbit;
  explicit OrbitFixture(const StepOptions& options)
      : model(paper_orbit_parameters()),
        stepper(model, options),
        map(stepper, make_grid(model.tau(), model.period(), 100)) {
    static const PeriodicOrbit reference = [&] {  // computed once for all tests (N = 100 only)
      OrbitBySimulationOptions o;
      o.tolerance = 1e-10;      // the checks need an orbit with impacts, not a converged one
      StepOptions one_substep;  // at N = 100 the default (4 sub-steps) orbit is not reached by simulation
      one_substep.contact_substeps = 1;
      const StroboscopicMap<ImpactModel> reference_map(TrapezoidStepper<ImpactModel>(model, one_substep), map.grid());
      return orbit_by_simulation(reference_map, map.constant_history(model.initial_state()), o);
    }();
    orbit = reference;
  }
};

// Checks every step of the orbit; returns the number of steps with events.
int expect_steps_match_fd(const OrbitFixture& f, double tolerance) {
  int event_steps = 0;
  double max_x = -INFINITY;
  for (const StepInput& in : step_inputs(f.map, f.orbit.history)) {
    StepEvents events;
    const StepJacobian J = step_jacobian(f.stepper, in, &events);
    const StepJacobian F = central_differences(f.stepper, in, kDelta);
    EXPECT_LE(relative_error(F, J), tolerance) << "step at t = " << in.t << " with " << events.count << " events";
    event_steps += events.count > 0;
    max_x = std::max(max_x, in.u0[0]);
  }
  EXPECT_GT(max_x, f.model.parameters().e) << "the orbit must impact";
  return event_steps;
}

StepOptions options(EventMode events, JacobianMode jacobian, int contact_substeps = 1) {
  StepOptions o;
  o.events = events;
  o.jacobian = jacobian;
  o.contact_substeps = contact_substeps;
  return o;
}

}  // namespace

TEST(EventStep, ConsistentStepMapsMatchFiniteDifferencesAlongImpactOrbit) {
  OrbitFixture f(options(EventMode::on, JacobianMode::consistent));
  EXPECT_GE(expect_steps_match_fd(f, kTolerance), 2);  // one entry and one exit per period
}

TEST(EventStep, ConsistentWithContactSubstepsMatchesFiniteDifferences) {
  OrbitFixture f(options(EventMode::on, JacobianMode::consistent, 4));
  EXPECT_GE(expect_steps_match_fd(f, kTolerance), 1);
}

TEST(EventStep, LinearEventTimesWithConsistentJacobianMatchFiniteDifferences) {
  OrbitFixture f(options(EventMode::linear, JacobianMode::consistent));
  EXPECT_GE(expect_steps_match_fd(f, kTolerance), 2);
}

TEST(EventStep, StroboscopicMapFiniteDifferencesMatchMonodromy) {
  OrbitFixture f(options(EventMode::on, JacobianMode::consistent));
  const Monodromy<2> M = f.map.monodromy(f.orbit.history);
  std::mt19937 rng(3);
  std::normal_distribution<double> gauss;
  // The whole map composes K = 100 steps, two with events: the same FD bound per step, amplified
  // by products of step maps of norm <= ~1.1 (the orbit is stable): 1e-6 still applies.
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd v(f.map.dimension());
    for (auto& x : v) x = gauss(rng);
    const Eigen::VectorXd fd =
        (f.map.apply(f.orbit.history + kDelta * v) - f.map.apply(f.orbit.history - kDelta * v)) / (2 * kDelta);
    Eigen::VectorXd Mv;
    M.apply(v, Mv);
    EXPECT_LE((fd - Mv).lpNorm<Eigen::Infinity>(), kTolerance * Mv.lpNorm<Eigen::Infinity>()) << "trial " << trial;
  }
}

TEST(EventStep, FrozenJacobianDisagreesWithFiniteDifferencesAtImpacts) {
  OrbitFixture f(options(EventMode::on, JacobianMode::frozen));
  double worst = 0;
  for (const StepInput& in : step_inputs(f.map, f.orbit.history)) {
    StepEvents events;
    const StepJacobian J = step_jacobian(f.stepper, in, &events);
    if (events.count > 0) worst = std::max(worst, relative_error(central_differences(f.stepper, in, kDelta), J));
  }
  // Frozen split points drop ds/du times the jump of f' across the event: O(1) here.
  EXPECT_GT(worst, 1e-2);
}

TEST(EventStep, GrazingStepConsistentMatchesFrozenDoesNot) {
  const GrazingCase g = grazing_case(1e-4);
  const ImpactModel model(g.parameters);
  const TrapezoidStepper<ImpactModel> consistent(model, options(EventMode::on, JacobianMode::consistent));
  const TrapezoidStepper<ImpactModel> frozen(model, options(EventMode::on, JacobianMode::frozen));
  StepEvents events;
  const StepJacobian J = step_jacobian(consistent, g.input, &events);
  ASSERT_EQ(events.count, 2);  // in and out within the step
  EXPECT_EQ(events.new_region[0], 1);
  EXPECT_EQ(events.new_region[1], 2);
  EXPECT_LT(events.offset[0], g.s_max);
  EXPECT_GT(events.offset[1], g.s_max);
  // Contact time ~ sqrt(8 p / |x''|) ~ 0.03: the FD step must stay well inside it; 1e-7 gives a
  // truncation error delta^2 |s'''| with |s'''| ~ c^-3 ~ 4e4: ~4e-10, rounding ~1e-9.
  const StepJacobian F = central_differences(consistent, g.input, 1e-7);
  EXPECT_LE(relative_error(F, J), kTolerance);
  // With both trapezoid nodes of the contact piece on H = 0, the nonlinear step does not feel
  // the contact force, but the frozen Jacobian applies A_1 across it (design.md 1.5).
  EXPECT_GT(relative_error(F, step_jacobian(frozen, g.input)), 1e-3);
}

TEST(EventStep, EventsOffIsThePlainTrapezoid) {
  OrbitFixture f(options(EventMode::off, JacobianMode::consistent));
  for (const StepInput& in : step_inputs(f.map, f.orbit.history)) {
    StepMap<2> a, b;
    StepEvents events;
    const V2 ya = f.stepper.step(in.t, in.h, in.u0, in.w0, in.w1, a, &events);
    const V2 yb = f.stepper.plain_step(in.t, in.h, in.u0, in.w0, in.w1, b);
    EXPECT_EQ(events.count, 0);
    EXPECT_EQ(ya, yb);
    EXPECT_EQ(as_matrix(a), as_matrix(b));
  }
}

TEST(EventStep, StepWithoutEventsInFreeFlightEqualsPlainTrapezoid) {
  // Away from the obstacle the event step is one region-2 piece: the plain trapezoid. Both
  // solve the same 2x2 linear system; results agree to rounding (a few ulps of |y| ~ 1).
  OrbitFixture f(options(EventMode::on, JacobianMode::consistent));
  int free_steps = 0;
  for (const StepInput& in : step_inputs(f.map, f.orbit.history)) {
    if (in.u0[0] > 1.0) continue;  // near the obstacle: may be an event step
    ++free_steps;
    StepMap<2> a, b;
    const V2 ya = f.stepper.step(in.t, in.h, in.u0, in.w0, in.w1, a);
    const V2 yb = f.stepper.plain_step(in.t, in.h, in.u0, in.w0, in.w1, b);
    EXPECT_LE((ya - yb).lpNorm<Eigen::Infinity>(), 1e-14);
    EXPECT_LE((as_matrix(a) - as_matrix(b)).lpNorm<Eigen::Infinity>(), 1e-14);
  }
  EXPECT_GT(free_steps, 50);
}

// fixed_region = 2: the free-flight field on every step, the contact ignored: the same step and
// step map as the model without a contact force (beta = 0: its two fields are one) stepped
// plainly, on the steps of an orbit with impacts (some in contact), and no event reported. To
// rounding, not bit for bit: the plain step's region is not fixed, so its affine solve takes a
// second, confirming iteration (stepper.hpp), a few ulps of |y| ~ 1. With the contact force
// (region 1 at the nodes in contact) the steps in contact would differ by O(beta h) ~ 0.6.
// Regions other than 0, 1, 2 are BadInput.
TEST(EventStep, AFixedRegionStepsThatRegionsFieldThroughTheContact) {
  OrbitFixture f(options(EventMode::on, JacobianMode::consistent));
  StepOptions free = options(EventMode::on, JacobianMode::consistent);
  free.fixed_region = 2;
  const TrapezoidStepper<ImpactModel> fixed(f.model, free);
  ImpactParameters no_contact = f.model.parameters();
  no_contact.beta = 0;
  const ImpactModel smooth(no_contact);
  const TrapezoidStepper<ImpactModel> plain(smooth, options(EventMode::off, JacobianMode::consistent));
  int in_contact = 0;
  for (const StepInput& in : step_inputs(f.map, f.orbit.history)) {
    in_contact += in.u0[0] > f.model.parameters().e;
    StepMap<2> a, b;
    StepEvents events;
    const V2 ya = fixed.step(in.t, in.h, in.u0, in.w0, in.w1, a, &events);
    const V2 yb = plain.step(in.t, in.h, in.u0, in.w0, in.w1, b);
    EXPECT_EQ(events.count, 0);
    EXPECT_LE((ya - yb).lpNorm<Eigen::Infinity>(), 1e-14);
    EXPECT_LE((as_matrix(a) - as_matrix(b)).lpNorm<Eigen::Infinity>(), 1e-14);
  }
  EXPECT_GT(in_contact, 0);
  free.fixed_region = 3;
  EXPECT_THROW(TrapezoidStepper<ImpactModel>(f.model, free), BadInput);
}

TEST(EventStep, ContactSubstepsMustBePositive) {
  const ImpactModel model;
  EXPECT_THROW(TrapezoidStepper<ImpactModel>(model, options(EventMode::on, JacobianMode::consistent, 0)), BadInput);
}

namespace {

// The excursion test as it was before its shortcut (dbf5fbd): the interior extrema of the Hermite
// cubic from the roots of its derivative, every time; with minima_only, the minima of into p.
bool hermite_extremum_within_by_roots(double ga, double gL, double d0, double d1, double margin, double into,
                                      bool minima_only) {
  const double c1 = d0, c2 = -3 * ga - 2 * d0 + 3 * gL - d1, c3 = 2 * ga + d0 - 2 * gL + d1;
  const double qa = 3 * c3, qb = 2 * c2, qc = c1;
  double roots[2];
  int n = 0;
  if (std::abs(qa) <= 1e-14 * (std::abs(qb) + std::abs(qc))) {
    if (qb != 0) roots[n++] = -qc / qb;
  } else {
    const double disc = qb * qb - 4 * qa * qc;
    if (disc >= 0) {
      const double q = -0.5 * (qb + std::copysign(std::sqrt(disc), qb));
      if (q != 0) roots[n++] = q / qa;
      roots[n++] = q != 0 ? qc / q : -qb / (2 * qa);
    }
  }
  for (int i = 0; i < n; ++i) {
    const double tau = roots[i];
    if (!(tau > 0 && tau < 1)) continue;
    if (minima_only && into * (2 * c2 + 6 * c3 * tau) < 0) continue;  // a maximum of into p
    if (into * (ga + tau * (c1 + tau * (c2 + tau * c3))) < margin) return true;
  }
  return false;
}

}  // namespace

// The shortcut of the excursion test (skip the roots when the chord bound puts the whole cubic
// beyond the margin) never changes its answer: random cubics at all distances from H = 0, on
// both sides, with the distance concentrated near the shortcut's own boundary min - deviation
// = margin, where a wrong bound would show.
TEST(EventStep, ExcursionTestShortcutGivesTheAnswerOfTheRoots) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  int answers[2] = {0, 0}, near_boundary = 0;
  for (int i = 0; i < 400000; ++i) {
    const double scale = std::pow(10.0, 4 * u(rng));  // slopes from 1e-4 to 1e4
    const double d0 = scale * u(rng), d1 = scale * u(rng);
    const double into = u(rng) > 0 ? 1 : -1;
    const double margin = std::abs(d1 - d0) + 1e-14 * std::abs(u(rng));
    double ga = into * scale * 2 * u(rng), gL = ga + scale * u(rng);
    if (i % 2 == 0) {  // shift the cubic so that its bound sits just at the margin
      const double deviation = 0.25 * std::max(std::abs(d0 - (gL - ga)), std::abs(d1 - (gL - ga)));
      // into * p >= min(into ga, into gL) - deviation: put that minimum at margin + deviation + noise
      const double target = margin + deviation + scale * 1e-9 * u(rng);
      const double shift = into * (target - std::min(into * ga, into * gL));
      ga += shift, gL += shift;
      ++near_boundary;
    }
    const bool minima_only = i % 4 >= 2;
    const bool expected = hermite_extremum_within_by_roots(ga, gL, d0, d1, margin, into, minima_only);
    ASSERT_EQ(detail::hermite_extremum_within(ga, gL, d0, d1, margin, into, minima_only), expected)
        << "ga " << ga << " gL " << gL << " d0 " << d0 << " d1 " << d1 << " margin " << margin << " into " << into
        << " minima_only " << minima_only;
    ++answers[expected];
  }
  EXPECT_GT(answers[0], 1000);  // both answers occur often: the comparison is not vacuous
  EXPECT_GT(answers[1], 1000);
  EXPECT_GT(near_boundary, 1000);
}

// The excursion test with minima only (pieces whose ends are both inside) on pieces of smooth
// H(s), s in [0, L], L = 0.01, both ends inside (into H > 0), one turning point s* in
// (0.1 L, 0.9 L):
// - a dip: into H = -delta + c x^2 + 0.01 e x^3 + f x^4, x = s - s*, c in [0.5, 2], |e| <= 5,
//   |f| <= 10 (convex on the piece), reaching delta in [1e-13, 1e-7] beyond H = 0: always
//   suspected. The Hermite cubic of the step's data (values and L H' at the ends, as
//   event_step.hpp forms them) is within max|H''''| L^4 / 384 <= 6e-9 of H, far inside the margin
//   |d1 - d0| ~ 2 c L^2 >= 1e-4, so its minimum is within the margin of H = 0;
// - a turn back into the region, into H = m0 - (c x^2 + ...), the top m0 in [0, c L^2 / 2]
//   (within the margin): not suspected with minima only, suspected without (the maximum within
//   the margin: what cost the exact searches for nothing in shallow contacts).
TEST(EventStep, ExcursionTestMinimaOnlyIgnoresTopsAndFindsEveryDip) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  const double L = 0.01;
  int dips = 0, tops = 0;
  for (int i = 0; i < 100000; ++i) {
    const double into = u(rng) < 0.5 ? 1 : -1;
    const double s_star = L * (0.1 + 0.8 * u(rng));
    const double c = 0.5 + 1.5 * u(rng), e = 10 * u(rng) - 5, f = 20 * u(rng) - 10;
    const bool dip = i % 2 == 0;
    const double level = dip ? -std::pow(10.0, -13 + 6 * u(rng)) : 0.5 * c * L * L * u(rng);
    const double sign = dip ? 1 : -1;  // into H convex (dip) or concave (top)
    auto H = [&](double s) {
      const double x = s - s_star;
      return into * (level + sign * (c * x * x + 1e-2 * e * x * x * x + f * x * x * x * x));
    };
    auto dH = [&](double s) {
      const double x = s - s_star;
      return into * sign * (2 * c * x + 3e-2 * e * x * x + 4 * f * x * x * x);
    };
    const double ga = H(0), gL = H(L), d0 = L * dH(0), d1 = L * dH(L);
    if (!(into * ga > 0 && into * gL > 0)) continue;  // an end outside: case 1, not this test
    const double margin = std::abs(d1 - d0);
    if (dip) {
      ++dips;
      ASSERT_TRUE(detail::hermite_extremum_within(ga, gL, d0, d1, margin, into, true))
          << "missed a dip of " << -level << " at " << s_star / L << " L, into " << into;
    } else {
      ++tops;
      ASSERT_FALSE(detail::hermite_extremum_within(ga, gL, d0, d1, margin, into, true))
          << "suspected a top at " << level << " within margin " << margin;
      ASSERT_TRUE(detail::hermite_extremum_within(ga, gL, d0, d1, margin, into, false)) << "top " << level;
    }
  }
  EXPECT_GT(dips, 10000);
  EXPECT_GT(tops, 5000);
}
