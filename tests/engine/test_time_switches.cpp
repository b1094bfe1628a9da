// Time switches (model.hpp, detail/time_switch_step.hpp): a field that changes at known times is
// split exactly there. Checked against the trapezoid rule written out by hand on the pieces
// (an identity of the discrete map), the exact solution (order 2 located, order 1 not), and the
// step map against differences of the step itself.
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "delayspec/model_milling.hpp"
#include "delayspec/stepper.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec {
namespace {

constexpr double kPi = std::numbers::pi;

// x' = c(t) x + b x(t - 1), c = c_in on the window [open, close) (mod 1), else c_out; tau = T = 1.
// Branch 2 inside the window, 1 outside.
class WindowModel {
 public:
  static constexpr int d = 1;
  static constexpr bool has_switching = false;
  static constexpr bool has_time_switches = true;
  static constexpr bool affine_in_state = true;
  static constexpr bool is_linear = true;
  using V = Vec<1>;
  using M = Mat<1>;
  double open = 0.3, close = 0.45, c_in = -2, c_out = 0.5, b = 0;

  double tau() const { return 1; }
  double period() const { return 1; }
  int time_segment(double t) const {
    const double phase = t - std::floor(t);
    return phase >= open && phase < close ? 2 : 1;
  }
  double next_time_switch(double t0, double t1) const {
    double next = t1;
    for (double edge : {open, close}) {
      double s = std::floor(t0) + edge;
      while (s <= t0) s += 1;
      next = std::min(next, s);
    }
    return next;
  }
  double c(int j) const { return j == 2 ? c_in : c_out; }
  V f(int j, double, const V& y, const V& y_tau) const { return V(c(j) * y[0] + b * y_tau[0]); }
  M A(int j, double, const V&, const V&) const { return M::Constant(c(j)); }
  M B(int, double, const V&, const V&) const { return M::Constant(b); }
  double H(const V&) const { return 1; }
  V grad_H(const V&) const { return V::Zero(); }
  V initial_state() const { return V(1); }
};

// x(1) of the ODE (b = 0) from x(0) = 1 by the stroboscopic map at resolution N.
double ode_period(const WindowModel& model, int N, EventMode events) {
  StepOptions options;
  options.events = events;
  const StroboscopicMap<WindowModel> map(TrapezoidStepper<WindowModel>(model, options), make_grid(1, 1, N));
  return map.apply(map.constant_history(Vec<1>(1)))[N];  // u_0 is the last block
}

// The trapezoid rule on x' = c x written out: a piece of length L in branch c multiplies x by
// (1 + c L / 2) / (1 - c L / 2). Pieces: the grid steps, split at the window's edges inside them.
double trapezoid_by_hand(const WindowModel& model, int N) {
  const double h = 1.0 / N;
  double x = 1;
  for (int i = 0; i < N; ++i) {
    std::vector<double> cuts = {i * h};
    for (double edge : {model.open, model.close})
      if (edge > i * h && edge < (i + 1) * h) cuts.push_back(edge);
    cuts.push_back((i + 1) * h);
    for (size_t p = 1; p < cuts.size(); ++p) {
      const double L = cuts[p] - cuts[p - 1], c = model.c(model.time_segment(0.5 * (cuts[p] + cuts[p - 1])));
      x *= (1 + 0.5 * c * L) / (1 - 0.5 * c * L);
    }
  }
  return x;
}

double exact_ode_period(const WindowModel& m) {
  return std::exp(m.c_in * (m.close - m.open) + m.c_out * (1 - (m.close - m.open)));
}

// Each step's result is rounded once per piece: N to 3N roundings of a product near 1, so a
// relative 1e-13 is ~50 ulp of headroom at N = 100.
constexpr double kRoundingTolerance = 1e-13;

TEST(TimeSwitches, LocatedStepIsTheTrapezoidOnEachPiece) {
  WindowModel model;  // edges 0.3 and 0.45 fall inside steps for N = 7 and 100 (not on nodes)
  for (int N : {7, 100})
    EXPECT_NEAR(ode_period(model, N, EventMode::on), trapezoid_by_hand(model, N), kRoundingTolerance);
}

TEST(TimeSwitches, WindowShorterThanAStep) {
  WindowModel model;
  model.open = 0.3031, model.close = 0.3047, model.c_in = -30;  // inside step [0.30, 0.31) at N = 100
  const double located = ode_period(model, 100, EventMode::on), exact = exact_ode_period(model);
  EXPECT_NEAR(located, trapezoid_by_hand(model, 100), kRoundingTolerance);
  // Located, the error is the trapezoid's (|c L| <= 0.05 per piece: ~1e-5 relative); the grid
  // alone never sees the window, whose effect is exp(-30 * 0.0016) - 1 = -4.7 %.
  EXPECT_LT(std::abs(located - exact), 1e-4 * exact);
  const double unlocated = ode_period(model, 100, EventMode::off);
  EXPECT_NEAR(unlocated, std::pow((1 + 0.005 * model.c_out) / (1 - 0.005 * model.c_out), 100), kRoundingTolerance);
  EXPECT_GT(std::abs(unlocated - exact), 0.04 * exact);
}

TEST(TimeSwitches, WindowOnGridNodesIsNotSplit) {
  WindowModel model;
  model.open = 0.25, model.close = 0.5;  // nodes 25 and 50 at N = 100 (0.25 = 25 h up to rounding)
  // By hand: whole steps, each in the branch of its midpoint (no piece shorter than rounding).
  const int N = 100;
  double x = 1;
  for (int i = 0; i < N; ++i) {
    const double c = model.c(model.time_segment((i + 0.5) / N)), L = 1.0 / N;
    x *= (1 + 0.5 * c * L) / (1 - 0.5 * c * L);
  }
  EXPECT_NEAR(ode_period(model, N, EventMode::on), x, kRoundingTolerance);
  // A switch reported one ulp before or after a node is the node (merged), not a piece.
  struct OffByOneUlp : WindowModel {
    double next_time_switch(double t0, double t1) const {
      const double s = WindowModel::next_time_switch(t0, t1);
      return s < t1 ? std::nextafter(s, s + (s > 0.4 ? 1 : -1)) : s;
    }
  };
  std::array<double, detail::kMaxTimeSwitchesPerStep + 2> offsets;
  OffByOneUlp shifted;
  shifted.open = 0.25, shifted.close = 0.5;
  EXPECT_EQ(detail::time_switch_offsets(shifted, 0.24, 0.01, offsets), 1);  // node at 0.25, computed below
  EXPECT_EQ(detail::time_switch_offsets(shifted, 0.49, 0.01, offsets), 1);  // node at 0.5, computed above
  EXPECT_EQ(detail::time_switch_offsets(shifted, 0.25, 0.01, offsets), 1);
  EXPECT_EQ(detail::time_switch_offsets(model, 0.2, 0.1, offsets), 2);  // a true interior switch
  EXPECT_DOUBLE_EQ(offsets[1], 0.05);
}

// Errors against the exact solution: located, order 2 (the error ratio at doubling N tends to 4:
// each piece's local error is O(L^3) whatever the jump); not located, order 1 (a step across the
// jump errs by O(h |c_in - c_out|)).
TEST(TimeSwitches, OrderTwoLocatedOrderOneNot) {
  WindowModel model;
  model.open = 1.0 / 3, model.close = 0.5 + 1e-3;  // not aligned with any power-of-two N
  const double exact = exact_ode_period(model);
  auto order = [&](EventMode events, int N) {
    const double e1 = std::abs(ode_period(model, N, events) - exact);
    const double e2 = std::abs(ode_period(model, 2 * N, events) - exact);
    return std::log2(e1 / e2);
  };
  for (int N : {64, 256, 1024}) EXPECT_NEAR(order(EventMode::on, N), 2.0, 0.05) << "N = " << N;
  // Not located: the observed order fluctuates around 1 with where the edges fall in a step.
  double mean = 0;
  for (int N : {64, 128, 256, 512, 1024, 2048}) mean += order(EventMode::off, N) / 6;
  EXPECT_NEAR(mean, 1.0, 0.3);
}

// The step map of a split step against the step itself: for a linear model the step is linear in
// (u0, w0, w1), so z(x + e) - z(x) = J e to rounding (no truncation error in the difference).
TEST(TimeSwitches, StepMapOfASplitStepIsTheStepsDerivative) {
  MillingParameters p;
  p.radial_immersion = 0.05;  // a jump of h(t) at the entry
  const MillingModel model(p);
  const TrapezoidStepper<MillingModel> stepper(model);
  const double T = model.period();
  // Steps that contain the entry of tooth 0, both edges of a window shorter than the step, and one
  // whose start is a switch (a window entry exactly on the node).
  const double entry = model.entry_angle() / (2 * kPi * p.spindle_rpm / 60);
  struct Case {
    double t, h;
  };
  for (const Case c : {Case{entry - 0.3 * T / 50, T / 50}, Case{entry - T / 4, T}, Case{entry, T / 50}}) {
    Vec<2> u0(1e-5, -2e-3), w0(3e-6, 1e-3), w1(-2e-6, 4e-3);
    StepMap<2> map;
    const Vec<2> z = stepper.step(c.t, c.h, u0, w0, w1, map);
    for (int k = 0; k < 2; ++k) {
      Vec<2> e = Vec<2>::Zero();
      e[k] = 1e-5;
      StepMap<2> unused;
      // Each difference is a sum of terms of size |J e| computed to a few ulp of |z| + |J e|.
      auto expect_column = [&](const Vec<2>& difference, const Vec<2>& predicted, const char* what) {
        EXPECT_LT((difference - predicted).norm(), 1e-12 * (z.norm() + predicted.norm()))
            << what << " column " << k << ", t = " << c.t << ", h = " << c.h;
      };
      expect_column(stepper.step(c.t, c.h, u0 + e, w0, w1, unused) - z, map.P * e, "P");
      expect_column(stepper.step(c.t, c.h, u0, w0 + e, w1, unused) - z, map.Q * e, "Q");
      expect_column(stepper.step(c.t, c.h, u0, w0, w1 + e, unused) - z, map.R * e, "R");
    }
  }
}

TEST(MillingModel, WindowsAndCuttingCoefficient) {
  MillingParameters p;
  p.radial_immersion = 0.5;  // down-milling: phi_st = arccos(0) = pi/2, phi_ex = pi
  const MillingModel model(p);
  EXPECT_DOUBLE_EQ(model.entry_angle(), kPi / 2);
  const double spin = 2 * kPi * p.spindle_rpm / 60, T = model.period();
  EXPECT_DOUBLE_EQ(T, 60 / (2 * p.spindle_rpm));
  // Tooth 0 cuts for phi in [pi/2, pi), tooth 1 (offset pi) for phi in [-pi/2, 0) mod 2 pi.
  EXPECT_EQ(model.time_segment(0.75 * kPi / spin), 1 + 1);
  EXPECT_EQ(model.time_segment(0.25 * kPi / spin), 1);
  EXPECT_EQ(model.time_segment(1.75 * kPi / spin), 1 + 2);
  EXPECT_NEAR(model.next_time_switch(0, T), 0.5 * kPi / spin, 1e-15 * T);
  EXPECT_NEAR(model.next_time_switch(0.5 * kPi / spin, 10 * T), kPi / spin, 1e-15 * T);
  const double phi = 0.7 * kPi;
  EXPECT_NEAR(model.cutting_coefficient(2, phi / spin), std::sin(phi) * (p.Kt * std::cos(phi) + p.Kn * std::sin(phi)),
              1e-7 * p.Kt);
  EXPECT_EQ(model.cutting_coefficient(1, phi / spin), 0);
  // h is T-periodic: tooth 1 at t + T is tooth 0 at t.
  EXPECT_EQ(model.time_segment(0.75 * kPi / spin + T), 1 + 2);
}

}  // namespace
}  // namespace delayspec
