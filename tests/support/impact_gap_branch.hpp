#pragma once
// The impact model at tau = T continued in the gap e (continuation's tests). On a T-periodic orbit
// the feedback k (v(t - T) - v(t)) vanishes, also for the discrete orbit (v_{l - N} = v_l), so
// without contact the orbit is the free forced oscillator's, x = A sin(w t - phi), A = a w^2 /
// sqrt((1 - w^2)^2 + (2 zeta w)^2): it grazes the wall x = e at e = A.
#include <cmath>
#include <numbers>

#include <Eigen/Core>

#include "delayspec/model_impact.hpp"

namespace delayspec::testing {

inline double free_amplitude(const ImpactParameters& p) {
  const double w = p.omega;
  return p.a * w * w / std::hypot(1 - w * w, 2 * p.zeta * w);
}

// The free orbit sampled at the N steps of one period (states x, v): the continuation's start,
// exact up to the trapezoid rule's O(h^2).
inline Eigen::VectorXd free_orbit_sequence(const ImpactParameters& p, int N) {
  const double w = p.omega, A = free_amplitude(p), h = 2 * std::numbers::pi / w / N;
  const double phi = std::atan2(2 * p.zeta * w, 1 - w * w);
  Eigen::VectorXd x(2 * N);
  for (int l = 0; l < N; ++l) {
    x[2 * l] = A * std::sin(w * l * h - phi);
    x[2 * l + 1] = A * w * std::cos(w * l * h - phi);
  }
  return x;
}

// The model at gap e, the other parameters `base`'s with the gain k.
struct ImpactInGap {
  ImpactParameters base;
  double k = 0.5;
  ImpactModel operator()(double e) const {
    ImpactParameters p = base;
    p.e = e;
    p.k = k;
    return ImpactModel(p);
  }
};

}  // namespace delayspec::testing
