#pragma once
// Mackey-Glass equation  x' = beta x_tau / (1 + x_tau^n) - gamma x,  x_tau = x(t - tau),
// d = 1, autonomous (no forcing): the stroboscopic period T is a free choice of the user (it
// only sets how often the Lyapunov QR and the Poincare samples happen). Classical values
// beta = 0.2, gamma = 0.1, n = 10; chaotic for tau = 17 and tau = 23.
// Affine in the current state (one linear solve per trapezoid step), nonlinear in the delayed one.
#include <cmath>

#include "delayspec/errors.hpp"
#include "delayspec/model.hpp"

namespace delayspec {

struct MackeyGlassParameters {
  double beta = 0.2;
  double gamma = 0.1;
  double n = 10;
  double tau = 17;
  double period = 17;  // T of the stroboscopic map (a time)
  double x0 = 0.5;     // constant initial history
};

class MackeyGlassModel {
 public:
  static constexpr int d = 1;
  static constexpr bool has_switching = false;
  static constexpr bool affine_in_state = true;
  static constexpr bool autonomous = true;  // no forcing: equilibria (equilibrium.hpp)
  static constexpr bool is_linear = false;
  using V = Vec<1>;
  using M = Mat<1>;

  explicit MackeyGlassModel(const MackeyGlassParameters& p = {}) : p_(p) {
    require_finite("beta", p.beta);
    require_finite("gamma", p.gamma);
    require_positive("n", p.n);
    require_positive("tau", p.tau);
    require_positive("period", p.period);
    require_finite("x0", p.x0);
    if (p.x0 < 0) throw BadInput("`x0 = " + format_number(p.x0) + "`: must be >= 0 (x_tau^n needs x >= 0)");
  }
  const MackeyGlassParameters& parameters() const { return p_; }
  double tau() const { return p_.tau; }
  double period() const { return p_.period; }

  // g(s) = beta s / (1 + s^n)
  V f(int, double, const V& y, const V& y_tau) const {
    const double s = y_tau[0], sn = std::pow(s, p_.n);
    return V(p_.beta * s / (1 + sn) - p_.gamma * y[0]);
  }
  M A(int, double, const V&, const V&) const { return M::Constant(-p_.gamma); }
  // g'(s) = beta (1 + s^n - n s^n) / (1 + s^n)^2
  M B(int, double, const V&, const V& y_tau) const {
    const double s = y_tau[0], sn = std::pow(s, p_.n);
    return M::Constant(p_.beta * (1 + sn - p_.n * sn) / ((1 + sn) * (1 + sn)));
  }
  double H(const V&) const { return 1; }
  V grad_H(const V&) const { return V::Zero(); }
  V initial_state() const { return V(p_.x0); }

 private:
  MackeyGlassParameters p_;
};

}  // namespace delayspec
