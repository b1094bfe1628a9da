// The Mackey-Glass model: values by hand, the Jacobian blocks against central finite
// differences, bad parameters rejected by name.
#include <gtest/gtest.h>

#include <cmath>

#include "delayspec/model_mackey_glass.hpp"

using delayspec::BadInput;
using delayspec::MackeyGlassModel;
using delayspec::MackeyGlassParameters;
using V = delayspec::Vec<1>;

TEST(MackeyGlass, RightHandSideByHand) {
  MackeyGlassModel model;
  // x_tau = 1: g = 0.2 * 1 / (1 + 1) = 0.1; minus 0.1 x with x = 2.
  EXPECT_DOUBLE_EQ(model.f(1, 0, V(2), V(1))[0], 0.1 - 0.2);
  // g'(1) = beta (1 + 1 - 10) / 4 = -0.4
  EXPECT_DOUBLE_EQ(model.B(1, 0, V(2), V(1))(0, 0), -0.4);
  EXPECT_DOUBLE_EQ(model.A(1, 0, V(2), V(1))(0, 0), -0.1);
}

TEST(MackeyGlass, JacobianMatchesCentralDifferences) {
  MackeyGlassModel model;
  const double step = 1e-6;
  for (double s : {0.0, 0.3, 0.9, 1.0, 1.2, 1.5}) {
    for (double x : {0.1, 1.1}) {
      const double fd_b = (model.f(1, 0, V(x), V(s + step))[0] - model.f(1, 0, V(x), V(s - step))[0]) / (2 * step);
      const double fd_a = (model.f(1, 0, V(x + step), V(s))[0] - model.f(1, 0, V(x - step), V(s))[0]) / (2 * step);
      // central differences: truncation O(step^2 f''') ~ 1e-12 * |f'''| (|f'''| < 1e3 here),
      // rounding eps |f| / step ~ 1e-10
      EXPECT_NEAR(model.B(1, 0, V(x), V(s))(0, 0), fd_b, 1e-8) << "s = " << s;
      EXPECT_NEAR(model.A(1, 0, V(x), V(s))(0, 0), fd_a, 1e-8) << "x = " << x;
    }
  }
}

TEST(MackeyGlass, RejectsBadParameters) {
  auto with = [](auto set) {
    MackeyGlassParameters p;
    set(p);
    return p;
  };
  EXPECT_THROW(MackeyGlassModel(with([](auto& p) { p.tau = 0; })), BadInput);
  EXPECT_THROW(MackeyGlassModel(with([](auto& p) { p.period = -1; })), BadInput);
  EXPECT_THROW(MackeyGlassModel(with([](auto& p) { p.n = 0; })), BadInput);
  EXPECT_THROW(MackeyGlassModel(with([](auto& p) { p.x0 = -0.5; })), BadInput);
  EXPECT_THROW(MackeyGlassModel(with([](auto& p) { p.beta = NAN; })), BadInput);
}
