#pragma once
// Soft-impact oscillator with time-delayed (Pyragas) feedback, paper eq. (2.2)-(2.3):
//
//   x' = v
//   v' = a w^2 sin(w t) + k (v(t - tau) - v(t)) - 2 zeta v - x - beta (x - e) Heaviside(x - e)
//
// y = (x, v), H(y) = x - e: region 1 (H > 0) is contact with the obstacle, region 2 free flight.
// The vector field is continuous across H = 0; its Jacobian A jumps by -beta in dv'/dx.
#include <cmath>
#include <numbers>

#include "delayspec/detail/remembered_trig.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/model.hpp"

namespace delayspec {

struct ImpactParameters {
  double zeta = 0.01;
  double e = 1.26;
  double a = 0.7;
  double beta = 28;
  double omega = 0.802;
  double k = 0;
  double tau_over_T = 1;  // used when tau <= 0 (not given)
  double tau = 0;         // delay in time units; 0 means "use tau_over_T"
  double x0 = 0, v0 = 0;  // constant initial history
};

class ImpactModel {
 public:
  static constexpr int d = 2;
  static constexpr bool has_switching = true;
  static constexpr bool affine_in_state = true;
  static constexpr bool is_linear = false;
  using V = Vec<2>;
  using M = Mat<2>;

  explicit ImpactModel(const ImpactParameters& p = {}) : p_(p) {
    require_nonnegative("zeta", p.zeta);
    require_finite("e", p.e);
    require_finite("a", p.a);
    require_nonnegative("beta", p.beta);
    require_positive("omega", p.omega);
    require_finite("k", p.k);
    require_finite("x0", p.x0);
    require_finite("v0", p.v0);
    require_nonnegative("tau", p.tau);
    if (p.tau > 0) {
      tau_ = p.tau;
    } else {
      require_positive("tau_over_T", p.tau_over_T);
      tau_ = p.tau_over_T * period();
    }
  }

  const ImpactParameters& parameters() const { return p_; }
  double tau() const { return tau_; }
  double period() const { return 2 * std::numbers::pi / p_.omega; }

  V f(int j, double t, const V& y, const V& y_tau) const {
    double contact = j == 1 ? p_.beta * (y[0] - p_.e) : 0.0;
    return V(y[1], p_.a * p_.omega * p_.omega * detail::remembered_sin(p_.omega * t) + p_.k * (y_tau[1] - y[1]) -
                       2 * p_.zeta * y[1] - y[0] - contact);
  }
  M A(int j, double, const V&, const V&) const {
    M a;
    a << 0, 1, -1 - (j == 1 ? p_.beta : 0.0), -p_.k - 2 * p_.zeta;
    return a;
  }
  M B(int, double, const V&, const V&) const {
    M b;
    b << 0, 0, 0, p_.k;
    return b;
  }
  // Explicit time derivatives of f (the forcing), for the event-time sensitivity of a split
  // step (event_step.hpp): df/dt and d2f/dt2 at fixed (y, y_tau).
  V f_t(int, double t, const V&, const V&) const {
    return V(0, p_.a * p_.omega * p_.omega * p_.omega * detail::remembered_cos(p_.omega * t));
  }
  V f_tt(int, double t, const V&, const V&) const {
    const double w2 = p_.omega * p_.omega;
    return V(0, -p_.a * w2 * w2 * detail::remembered_sin(p_.omega * t));
  }
  double H(const V& y) const { return y[0] - p_.e; }
  V grad_H(const V&) const { return V(1, 0); }
  V initial_state() const { return V(p_.x0, p_.v0); }

 private:
  ImpactParameters p_;
  double tau_ = 0;
};

}  // namespace delayspec
