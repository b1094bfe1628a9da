#pragma once
// The damped Mathieu ODE x'' + kappa x' + (delta + eps cos t) x = 0: the delayed Mathieu equation
// at b = 0. Its two multipliers, the eigenvalues of the monodromy over 2 pi, by classical
// Runge-Kutta with 20000 steps (error ~ h^4 = 1e-13): a reference the DDE code does not produce.
#include <array>
#include <cmath>
#include <complex>
#include <numbers>

namespace delayspec::testing {

inline std::array<std::complex<double>, 2> mathieu_ode_multipliers(double delta, double eps, double kappa) {
  auto f = [&](double t, const std::array<double, 2>& y) {
    return std::array<double, 2>{y[1], -(delta + eps * std::cos(t)) * y[0] - kappa * y[1]};
  };
  auto add = [](const std::array<double, 2>& a, const std::array<double, 2>& k, double s) {
    return std::array<double, 2>{a[0] + s * k[0], a[1] + s * k[1]};
  };
  std::array<std::array<double, 2>, 2> M{};  // column c: the solution from the c-th unit vector
  for (int c = 0; c < 2; ++c) {
    std::array<double, 2> y = {c == 0 ? 1.0 : 0.0, c == 1 ? 1.0 : 0.0};
    const int steps = 20000;
    const double h = 2 * std::numbers::pi / steps;
    for (int i = 0; i < steps; ++i) {
      const double t = i * h;
      const auto k1 = f(t, y), k2 = f(t + h / 2, add(y, k1, h / 2)), k3 = f(t + h / 2, add(y, k2, h / 2)),
                 k4 = f(t + h, add(y, k3, h));
      for (int r = 0; r < 2; ++r) y[r] += h / 6 * (k1[r] + 2 * k2[r] + 2 * k3[r] + k4[r]);
    }
    M[0][c] = y[0];
    M[1][c] = y[1];
  }
  const double tr = M[0][0] + M[1][1], det = M[0][0] * M[1][1] - M[0][1] * M[1][0];
  const std::complex<double> root = std::sqrt(std::complex<double>(tr * tr / 4 - det, 0));
  return {tr / 2 + root, tr / 2 - root};
}

}  // namespace delayspec::testing
