#pragma once
// Scalar linear DDE  x' = a x + b x(t - tau), with a stroboscopic period T chosen by the user.
// Its characteristic roots are known exactly (Lambert W, see lambert_w.hpp), which makes
// it the reference for the discretisation's convergence order.
#include "delayspec/errors.hpp"
#include "delayspec/model.hpp"

namespace delayspec {

struct LinearParameters {
  double a = -1;
  double b = 0.5;
  double tau = 1;
  double period = 1;  // T of the stroboscopic map (a time)
};

class LinearModel {
 public:
  static constexpr int d = 1;
  static constexpr bool has_switching = false;
  static constexpr bool affine_in_state = true;
  static constexpr bool autonomous = true;  // no forcing: equilibria (equilibrium.hpp)
  static constexpr bool is_linear = true;
  using V = Vec<1>;
  using M = Mat<1>;

  explicit LinearModel(const LinearParameters& p = {}) : p_(p) {
    require_finite("a", p.a);
    require_finite("b", p.b);
    require_positive("tau", p.tau);
    require_positive("period", p.period);
  }
  const LinearParameters& parameters() const { return p_; }
  double tau() const { return p_.tau; }
  double period() const { return p_.period; }
  V f(int, double, const V& y, const V& y_tau) const { return V(p_.a * y[0] + p_.b * y_tau[0]); }
  M A(int, double, const V&, const V&) const { return M::Constant(p_.a); }
  M B(int, double, const V&, const V&) const { return M::Constant(p_.b); }
  double H(const V&) const { return 1; }
  V grad_H(const V&) const { return V::Zero(); }
  V initial_state() const { return V(1); }

 private:
  LinearParameters p_;
};

}  // namespace delayspec
