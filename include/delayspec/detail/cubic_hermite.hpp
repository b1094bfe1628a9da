#pragma once
// The cubic Hermite interpolant on [0, 1] and its interior turning points: one home for the
// event test's excursion check (event_step.hpp: hermite_extremum_within) and continuation's
// largest value of a test function between two points (hermite_maximum: continuation's max H
// and the orbit's contacts, orbit_search.hpp).
//
// p(tau) = ga + c1 tau + c2 tau^2 + c3 tau^3 with p(0) = ga, p(1) = gL, p'(0) = d0, p'(1) = d1:
//   c1 = d0, c2 = -3 ga - 2 d0 + 3 gL - d1, c3 = 2 ga + d0 - 2 gL + d1.
// Its turning points are the roots of p'(tau) = c1 + 2 c2 tau + 3 c3 tau^2, taken in the stable
// form q = -(qb + sign(qb) sqrt(qb^2 - 4 qa qc)) / 2, roots q / qa and qc / q (no cancellation
// between -qb and the square root); a quadratic coefficient below 1e-14 of the others is a
// linear p' (its root -qc / qb), since q / qa would then be rounding divided by rounding.
#include <algorithm>
#include <cmath>

namespace delayspec::detail {

struct CubicHermite {
  double c0, c1, c2, c3;

  CubicHermite(double ga, double gL, double d0, double d1)
      : c0(ga), c1(d0), c2(-3 * ga - 2 * d0 + 3 * gL - d1), c3(2 * ga + d0 - 2 * gL + d1) {}

  double operator()(double tau) const { return c0 + tau * (c1 + tau * (c2 + tau * c3)); }
  // p''(tau) / 2: its sign tells a minimum (> 0) from a maximum.
  double half_curvature(double tau) const { return c2 + 3 * c3 * tau; }

  // The roots of p' (0, 1 or 2 of them, anywhere on the line) into `roots`; returns how many.
  int turning_points(double roots[2]) const {
    const double qa = 3 * c3, qb = 2 * c2, qc = c1;
    int n = 0;
    if (std::abs(qa) <= 1e-14 * (std::abs(qb) + std::abs(qc))) {
      if (qb != 0) roots[n++] = -qc / qb;
    } else {
      const double disc = qb * qb - 4 * qa * qc;
      if (disc >= 0) {
        const double q = -0.5 * (qb + std::copysign(std::sqrt(disc), qb));
        if (q != 0) roots[n++] = q / qa;
        roots[n++] = q != 0 ? qc / q : -qb / (2 * qa);
      }
    }
    return n;
  }
};

// The maximum of the cubic Hermite interpolant on [0, h] of values g0, g1 and slopes s0, s1 (in
// the variable on [0, h]): at an end or at an interior turning point.
inline double hermite_maximum(double g0, double g1, double s0, double s1, double h) {
  const CubicHermite g(g0, g1, h * s0, h * s1);
  double best = std::max(g0, g1);
  double roots[2];
  const int n = g.turning_points(roots);
  for (int i = 0; i < n; ++i)
    if (roots[i] > 0 && roots[i] < 1) best = std::max(best, g(roots[i]));
  return best;
}

}  // namespace delayspec::detail
