#pragma once
// Scalar searches on an interval, used by event location (event_step.hpp):
//
//   bracketed_root(g, a, b, ga, gb)   a root of g in [a, b] given a sign change (Brent's zeroin:
//                                     bisection safeguarding secant / inverse quadratic steps),
//                                     to machine precision in the abscissa;
//   bounded_minimum(g, a, b)          a local minimum of g on [a, b] (Brent's fmin: golden section
//                                     safeguarding parabolic steps), to about sqrt(eps) in the
//                                     abscissa (the value is then accurate to about eps).
//
// Both are the classic algorithms (R. P. Brent, "Algorithms for minimization without
// derivatives", 1973, ch. 4 and 5), written for a callable g(double) -> double. Neither
// allocates; both count evaluations so that callers can report them.
#include <algorithm>
#include <cmath>
#include <limits>

namespace delayspec {

struct ScalarSearchResult {
  double x = 0;  // the abscissa found
  double g = 0;  // g(x)
  int evaluations = 0;
};

// Requires g(a) = ga and g(b) = gb of opposite signs (or one of them zero). Returns x with
// g(x) = 0 or the end of a bracket of width <= 4 eps |x| + 2 tiny on which g changes sign
// (the end whose |g| is smaller).
template <class G>
ScalarSearchResult bracketed_root(const G& g, double a, double b, double ga, double gb, int max_evaluations = 200) {
  constexpr double eps = std::numeric_limits<double>::epsilon();
  constexpr double tiny = std::numeric_limits<double>::min();
  ScalarSearchResult r;
  if (ga == 0) return {a, 0, 0};
  if (gb == 0) return {b, 0, 0};
  double c = a, gc = ga, d = b - a, e = d;
  for (r.evaluations = 0; r.evaluations < max_evaluations;) {
    if ((gb > 0) == (gc > 0)) {  // keep the root between b and c
      c = a;
      gc = ga;
      d = e = b - a;
    }
    if (std::abs(gc) < std::abs(gb)) {  // b is the best estimate so far
      a = b, b = c, c = a;
      ga = gb, gb = gc, gc = ga;
    }
    const double tol = 2 * eps * std::abs(b) + 2 * tiny;
    const double half = 0.5 * (c - b);
    if (std::abs(half) <= tol || gb == 0) break;
    if (std::abs(e) >= tol && std::abs(ga) > std::abs(gb)) {
      // secant (two points) or inverse quadratic interpolation (three points)
      double p, q, s = gb / ga;
      if (a == c) {
        p = 2 * half * s;
        q = 1 - s;
      } else {
        const double qa = ga / gc, rb = gb / gc;
        p = s * (2 * half * qa * (qa - rb) - (b - a) * (rb - 1));
        q = (qa - 1) * (rb - 1) * (s - 1);
      }
      if (p > 0) q = -q;
      p = std::abs(p);
      if (2 * p < std::min(3 * half * q - std::abs(tol * q), std::abs(e * q))) {
        e = d;  // accept the interpolation
        d = p / q;
      } else {
        d = half;  // bisect
        e = d;
      }
    } else {
      d = half;
      e = d;
    }
    a = b;
    ga = gb;
    b += std::abs(d) > tol ? d : (half > 0 ? tol : -tol);
    gb = g(b);
    ++r.evaluations;
  }
  r.x = b;
  r.g = gb;
  return r;
}

// A local minimum of g on [a, b] (a < b), ends included as candidates.
template <class G>
ScalarSearchResult bounded_minimum(const G& g, double a, double b, int max_evaluations = 100) {
  constexpr double eps = std::numeric_limits<double>::epsilon();
  const double golden = 0.5 * (3 - std::sqrt(5.0));
  const double rel = std::sqrt(eps);
  ScalarSearchResult r;
  double x = a + golden * (b - a), w = x, v = x;
  double gx = g(x), gw = gx, gv = gx;
  r.evaluations = 1;
  double d = 0, e = 0;
  while (r.evaluations < max_evaluations) {
    const double mid = 0.5 * (a + b);
    const double tol = rel * std::abs(x) + 1e-300;
    const double tol2 = 2 * tol;
    if (std::abs(x - mid) <= tol2 - 0.5 * (b - a)) break;
    bool golden_step = true;
    if (std::abs(e) > tol) {  // try a parabola through x, w, v
      double rr = (x - w) * (gx - gv);
      double q = (x - v) * (gx - gw);
      double p = (x - v) * q - (x - w) * rr;
      q = 2 * (q - rr);
      if (q > 0) p = -p;
      q = std::abs(q);
      const double e_old = e;
      e = d;
      if (std::abs(p) < std::abs(0.5 * q * e_old) && p > q * (a - x) && p < q * (b - x)) {
        d = p / q;
        const double u = x + d;
        if (u - a < tol2 || b - u < tol2) d = x < mid ? tol : -tol;
        golden_step = false;
      }
    }
    if (golden_step) {
      e = (x >= mid ? a : b) - x;
      d = golden * e;
    }
    const double u = x + (std::abs(d) >= tol ? d : (d > 0 ? tol : -tol));
    const double gu = g(u);
    ++r.evaluations;
    if (gu <= gx) {
      if (u >= x) a = x;
      else b = x;
      v = w, gv = gw;
      w = x, gw = gx;
      x = u, gx = gu;
    } else {
      if (u < x) a = u;
      else b = u;
      if (gu <= gw || w == x) {
        v = w, gv = gw;
        w = u, gw = gu;
      } else if (gu <= gv || v == x || v == w) {
        v = u, gv = gu;
      }
    }
  }
  r.x = x;
  r.g = gx;
  return r;
}

}  // namespace delayspec
