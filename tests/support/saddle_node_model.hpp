#pragma once
// A scalar DDE with an exact fold of equilibria, for continuation's tests.
#include "delayspec/types.hpp"

namespace delayspec::testing {

// x' = p - x^2 + c (x(t - tau) - x): equilibria x = +-sqrt(p) for every c (the delayed term
// vanishes on a constant), joined by a fold at p = 0, where the characteristic equation
// lambda = -2 x - c + c exp(-lambda tau) has the root 0. A constant is a fixed point of the
// trapezoid step exactly when f = 0, so the discrete branch is the same and the discrete fold is
// at p = 0 exactly for every N.
struct SaddleNodeDelayModel {
  static constexpr int d = 1;
  static constexpr bool has_switching = false;
  static constexpr bool affine_in_state = false;
  static constexpr bool is_linear = false;
  using V = Vec<1>;
  using M = Mat<1>;
  double p = 1, c = 0.5;
  double tau() const { return 1; }
  double period() const { return 1; }
  V f(int, double, const V& y, const V& y_tau) const { return V(p - y[0] * y[0] + c * (y_tau[0] - y[0])); }
  M A(int, double, const V& y, const V&) const { return M::Constant(-2 * y[0] - c); }
  M B(int, double, const V&, const V&) const { return M::Constant(c); }
  double H(const V&) const { return 1; }
  V grad_H(const V&) const { return V::Zero(); }
  V initial_state() const { return V(1); }
};

}  // namespace delayspec::testing
