#pragma once
// One full trapezoid step of a model whose field switches at known times (model.hpp, "Time
// switches": a cutting window), split at the switches inside it, and its exact derivative.
//
// The switch times 0 < s_1 < ... < s_{n-1} < h inside the step [t, t + h] come from the model
// and do not depend on the state. Each piece [s_{p-1}, s_p] is one trapezoid sub-step in the
// branch j_p in force on the open piece (the branch at its midpoint), both nodes evaluated with
// that branch's formula:
//
//   z_p = z_{p-1} + L/2 [ f_j(t + s_{p-1}, z_{p-1}, w(s_{p-1})) + f_j(t + s_p, z_p, w(s_p)) ],
//   L = s_p - s_{p-1},   w(s) = (1 - s/h) w0 + (s/h) w1,
//
// where w0 = y_tau(t), w1 = y_tau(t + h) as in event_step.hpp (the delayed value inside the step
// is the linear interpolant of the two history blocks the step map uses). A jump of f at a switch
// then costs no order: every piece has a smooth integrand, so its local error is O(L^3), where
// the unsplit step across a jump errs by O(h |jump|) (first order globally).
//
// Step map: since the s_p do not move with (u0, w0, w1), the derivative of the step is the chain
// of the pieces' own maps, dz_p = J_p dz_{p-1} + (dz_p/dw(s_{p-1})) dw(s_{p-1}) + (dz_p/dw(s_p))
// dw(s_p), with dw(s) = (1 - s/h) dw0 + (s/h) dw1: the same form P du0 + Q dw0 + R dw1 as any step.
//
// Switches that fall within `merge` = 64 eps (|t| + h) of a node or of each other are one time
// computed twice with rounding (a window that opens exactly on a grid node may be computed an
// ulp before it): they are merged, so no piece is shorter than rounding. Dropping a piece of
// length delta changes the step by O(delta |jump|), below the rounding of z.
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "delayspec/errors.hpp"
#include "delayspec/model.hpp"
#include "delayspec/step_map.hpp"
#include "delayspec/step_options.hpp"

namespace delayspec {

template <class Model>
class TrapezoidStepper;  // stepper.hpp: its sub_step() is what a piece is

namespace detail {

// At most this many switches inside one step (a step longer than many windows): more is a
// NumericalFailure asking for a smaller step.
inline constexpr int kMaxTimeSwitchesPerStep = 64;

// The piece boundaries of the step [t, t + h]: offsets[0] = 0 < offsets[1] < ... <
// offsets[count] = h. Returns count (the number of pieces, >= 1).
template <class Model>
int time_switch_offsets(const Model& model, double t, double h,
                        std::array<double, kMaxTimeSwitchesPerStep + 2>& offsets) {
  const double merge = 64 * std::numeric_limits<double>::epsilon() * (std::abs(t) + h);
  int count = 0;
  offsets[0] = 0;
  for (double from = t;;) {
    const double s = model.next_time_switch(from, t + h);
    if (s >= t + h - merge) break;  // no further switch inside the step
    if (!(s > from))                // also NaN: the model must move forward, or this would not end
      throw NumericalFailure("time switch after t = " + format_number(from) + " reported at " + format_number(s) +
                             ": not later (the model's next_time_switch)");
    const double offset = s - t;
    if (offset > merge && offset - offsets[count] > merge) {
      if (count == kMaxTimeSwitchesPerStep)
        throw NumericalFailure("step at t = " + format_number(t) + ", h = " + format_number(h) + ": more than " +
                               std::to_string(kMaxTimeSwitchesPerStep) + " time switches in one step (increase N)");
      offsets[++count] = offset;
    }
    from = s;
  }
  offsets[++count] = h;
  return count;
}

// With several delays w0, w1 are the stacked taps (DW rows, model.hpp) and so are Q and R.
template <class Model>
Vec<Model::d> time_switch_step(const TrapezoidStepper<Model>& stepper, double t, double h, const Vec<Model::d>& u0,
                               const DelayedVec<Model>& w0, const DelayedVec<Model>& w1,
                               StepLinearisation<Model::d, delayed_rows<Model>>& linearisation) {
  constexpr int D = Model::d, DW = delayed_rows<Model>;
  const Model& model = stepper.model();
  std::array<double, kMaxTimeSwitchesPerStep + 2> s;
  const int pieces = time_switch_offsets(model, t, h, s);
  if (pieces == 1) {  // most steps: one piece, the plain step in the branch of the whole step
    const int j = model.time_segment(t + 0.5 * h);
    int jr;
    linearisation.factored = true;
    return stepper.factored_sub_step(t, h, u0, w0, w1, j, j, linearisation.sub, jr);
  }
  auto w_at = [&](double x) { return DelayedVec<Model>((1 - x / h) * w0 + (x / h) * w1); };
  Vec<D> z = u0;
  using Tangent = Eigen::Matrix<double, D, D + 2 * DW>;  // dz / d(u0, w0, w1)
  Tangent X = Tangent::Zero();
  X.template leftCols<D>().setIdentity();
  for (int p = 1; p <= pieces; ++p) {
    const double s0 = s[p - 1], s1 = s[p];
    const int j = model.time_segment(t + 0.5 * (s0 + s1));
    const SubStepResult<D, DW> r = stepper.sub_step(t + s0, s1 - s0, z, w_at(s0), w_at(s1), j, j);
    Tangent next = r.dz0 * X;
    next.template middleCols<DW>(D) += (1 - s0 / h) * r.dw0 + (1 - s1 / h) * r.dw1;
    next.template rightCols<DW>() += (s0 / h) * r.dw0 + (s1 / h) * r.dw1;
    X = next;
    z = r.z1;
  }
  linearisation.factored = false;
  linearisation.map.P = X.template leftCols<D>();
  linearisation.map.Q = X.template middleCols<DW>(D);
  linearisation.map.R = X.template rightCols<DW>();
  return z;
}

}  // namespace detail
}  // namespace delayspec
