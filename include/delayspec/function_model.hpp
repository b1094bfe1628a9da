#pragma once
// FunctionModel<S>: the model of model.hpp whose f, A, B, f_t, f_tt, H, grad_H and time switch
// are the plain functions of a ModelFunctions table (model_functions.hpp), of the shape S. The
// models written as equations in a scene are these (docs/models.md). One indirect call per
// evaluation is all it adds to a model compiled whole (bench_equations measures it).
#include <algorithm>
#include <array>
#include <vector>

#include "delayspec/model.hpp"
#include "delayspec/model_functions.hpp"
#include "delayspec/types.hpp"

namespace delayspec {

// A time switch's roots are looked for in this many equal sub-intervals of (t0, t1) (one step of
// the engine), each sign change then bisected to adjacent doubles: two roots within one
// sub-interval are missed (docs/models.md).
inline constexpr int kTimeSwitchSamples = 16;

template <ModelShape S>
class FunctionModel {
 public:
  static constexpr int d = S.d;
  static constexpr int delay_count = S.delay_count;
  static constexpr bool has_switching = S.switching == ModelSwitching::state;
  static constexpr bool has_time_switches = S.switching == ModelSwitching::time;
  static constexpr bool affine_in_state = S.affine_in_state;
  static constexpr bool is_linear = S.is_linear;
  static constexpr bool autonomous = S.autonomous;
  using Vector = Vec<d>;
  using Matrix = Mat<d>;
  using Delayed = Vec<d * delay_count>;
  using DelayedMatrix = RectMat<d, d * delay_count>;

  FunctionModel(const ModelFunctions& functions, const ModelValues& values)
      : fn_(&functions), p_(values.parameters, values.parameters + values.parameter_count), period_(values.period) {
    for (int k = 0; k < delay_count; ++k) delays_[k] = values.delays[k], tau_ = std::max(tau_, values.delays[k]);
    for (int i = 0; i < d; ++i) history_[i] = values.history[i];
    if constexpr (has_switching) {  // H affine in y (model.hpp; the equations' reader refuses others)
      const Vector zero = Vector::Zero();
      fn_->grad_H(zero.data(), p_.data(), grad_H_.data());
      H_at_zero_ = fn_->H(zero.data(), p_.data());
    }
  }

  double tau() const { return tau_; }
  std::array<double, delay_count> delays() const { return delays_; }
  double period() const { return period_; }
  Vector initial_state() const { return history_; }

  Vector f(int j, double t, const Vector& y, const Delayed& z) const { return field(fn_->f, j, t, y, z); }
  Vector f_t(int j, double t, const Vector& y, const Delayed& z) const { return field(fn_->f_t, j, t, y, z); }
  Vector f_tt(int j, double t, const Vector& y, const Delayed& z) const { return field(fn_->f_tt, j, t, y, z); }
  Matrix A(int j, double t, const Vector& y, const Delayed& z) const {
    Matrix r = Matrix::Zero();
    fn_->A(j, t, y.data(), z.data(), p_.data(), r.data());
    return r;
  }
  DelayedMatrix B(int j, double t, const Vector& y, const Delayed& z) const {
    DelayedMatrix r = DelayedMatrix::Zero();
    fn_->B(j, t, y.data(), z.data(), p_.data(), r.data());
    return r;
  }

  // H(y) = H(0) + grad_H . y, as H is affine: no call per evaluation (the event step evaluates H
  // many times per step in its root search). Measured on the impact equations' Lyapunov run
  // (bench_equations): 91.5 ns per step with H and grad_H called, against 75 ns for the model
  // compiled whole before. Equal to the printed H to rounding (the same terms summed in another
  // order; bit for bit when grad_H has one nonzero entry 1, as for `x - e`).
  double H(const Vector& y) const { return grad_H_.dot(y) + H_at_zero_; }
  Vector grad_H(const Vector&) const { return grad_H_; }

  // 1 where the switch is > 0, else 2.
  int time_segment(double t) const { return fn_->switch_value(t, p_.data()) > 0 ? 1 : 2; }
  // The sub-intervals of (t0, t1) are searched in order for a change of segment, which is then
  // bisected to adjacent doubles; the first double of the new segment is returned (> t0, as
  // time_switch_step.hpp requires), t1 when there is none.
  double next_time_switch(double t0, double t1) const {
    if (!(t1 > t0)) return t1;
    const int first = time_segment(t0);
    double a = t0;
    for (int i = 1; i <= kTimeSwitchSamples; ++i) {
      const double b = i == kTimeSwitchSamples ? t1 : t0 + (t1 - t0) * i / kTimeSwitchSamples;
      if (time_segment(b) != first) {
        double lo = a, hi = b;
        for (;;) {
          const double mid = lo + (hi - lo) / 2;
          if (!(mid > lo && mid < hi)) return hi;
          (time_segment(mid) == first ? lo : hi) = mid;
        }
      }
      a = b;
    }
    return t1;
  }

 private:
  Vector field(ModelFunctions::Field fn, int j, double t, const Vector& y, const Delayed& z) const {
    Vector r;
    fn(j, t, y.data(), z.data(), p_.data(), r.data());
    return r;
  }

  const ModelFunctions* fn_;
  std::vector<double> p_;
  std::array<double, delay_count> delays_{};
  double tau_ = 0, period_ = 0;
  Vector history_ = Vector::Zero();
  Vector grad_H_ = Vector::Zero();  // a state switch's constant gradient, and H(0)
  double H_at_zero_ = 0;
};

}  // namespace delayspec
