#pragma once
// The circle oscillator of test_autonomous_orbit.cpp and test_hopf_branch.cpp:
//
//   z' = (mu + i omega) z - |z|^2 z + k (|z(t - tau)|^2 - mu) z,   z = x + i y,
//
// whose circle |z|^2 = mu (mu > 0) is a periodic orbit of period 2 pi / omega for every tau and k
// (the delayed term vanishes on it), born at the Hopf point mu = 0 of the equilibrium z = 0
// (roots mu +- i omega). The discrete orbit and its multipliers in closed form: the tests' headers.
#include <cmath>

#include "delayspec/types.hpp"

namespace delayspec {

struct Circle {
  static constexpr int d = 2;
  static constexpr bool has_switching = false, affine_in_state = false, is_linear = false, autonomous = true;
  double omega = 2 * M_PI, k = 0.5, delay = 0.37, mu = 1;
  Vec<2> start{1.2, 0.0};
  double tau() const { return delay; }
  double period() const { return 1; }
  Vec<2> f(int, double, const Vec<2>& y, const Vec<2>& w) const {
    const double r2 = y.squaredNorm(), g = mu - r2 + k * (w.squaredNorm() - mu);
    return Vec<2>(g * y[0] - omega * y[1], omega * y[0] + g * y[1]);
  }
  Mat<2> A(int, double, const Vec<2>& y, const Vec<2>& w) const {
    const double g = mu - y.squaredNorm() + k * (w.squaredNorm() - mu);
    Mat<2> a;
    a << g - 2 * y[0] * y[0], -omega - 2 * y[0] * y[1], omega - 2 * y[0] * y[1], g - 2 * y[1] * y[1];
    return a;
  }
  Mat<2> B(int, double, const Vec<2>& y, const Vec<2>& w) const { return 2 * k * y * w.transpose(); }
  Vec<2> initial_state() const { return start; }
};

}  // namespace delayspec
