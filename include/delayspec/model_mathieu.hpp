#pragma once
// Delayed damped Mathieu equation  x'' + kappa x' + (delta + eps cos t) x = b x(t - 2 pi),
// tau = T = 2 pi, y = (x, v). Linear and T-periodic: the monodromy does not depend on an orbit.
// cos t through the per-thread memo (remembered_trig.hpp): the step times repeat every period.
#include <cmath>
#include <numbers>

#include "delayspec/detail/remembered_trig.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/model.hpp"

namespace delayspec {

struct MathieuParameters {
  double kappa = 0.1;
  double delta = 3;
  double eps = 2;
  double b = -0.15;
};

class MathieuModel {
 public:
  static constexpr int d = 2;
  static constexpr bool has_switching = false;
  static constexpr bool affine_in_state = true;
  static constexpr bool is_linear = true;
  using V = Vec<2>;
  using M = Mat<2>;

  explicit MathieuModel(const MathieuParameters& p = {}) : p_(p) {
    require_finite("kappa", p.kappa);
    require_finite("delta", p.delta);
    require_finite("eps", p.eps);
    require_finite("b", p.b);
  }
  const MathieuParameters& parameters() const { return p_; }
  double tau() const { return 2 * std::numbers::pi; }
  double period() const { return 2 * std::numbers::pi; }
  V f(int, double t, const V& y, const V& y_tau) const {
    return V(y[1], -p_.kappa * y[1] - (p_.delta + p_.eps * detail::remembered_cos(t)) * y[0] + p_.b * y_tau[0]);
  }
  M A(int, double t, const V&, const V&) const {
    M a;
    a << 0, 1, -(p_.delta + p_.eps * detail::remembered_cos(t)), -p_.kappa;
    return a;
  }
  M B(int, double, const V&, const V&) const {
    M b;
    b << 0, 0, p_.b, 0;
    return b;
  }
  double H(const V&) const { return 1; }
  V grad_H(const V&) const { return V::Zero(); }
  V initial_state() const { return V(1, 0); }

 private:
  MathieuParameters p_;
};

}  // namespace delayspec
