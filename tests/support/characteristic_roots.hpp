#pragma once
// The exact multipliers of a linear autonomous DDE with constant coefficients, from its
// characteristic function c(lambda) (e.g. lambda - a - b1 exp(-lambda tau1) - b2 exp(-lambda tau2)):
// Newton on c from a grid of starts over the rectangle [re_min, 3] x [-im_max, im_max], the distinct
// converged roots mapped to multipliers exp(lambda T), largest modulus first. A reference the engine
// does not produce (tests/engine/test_several_delays.cpp, tests/scene/test_equation_models.cpp).
#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <vector>

namespace delayspec::test {

struct Characteristic {
  std::function<std::complex<double>(std::complex<double>)> value, derivative;
};

// The distinct roots found in the rectangle, rightmost first.
inline std::vector<std::complex<double>> exact_roots(const Characteristic& ch, double re_min, double im_max) {
  using cd = std::complex<double>;
  std::vector<cd> roots;
  for (double re = re_min; re <= 3; re += 0.25)
    for (double im = -im_max; im <= im_max; im += 0.25) {
      cd l(re, im);
      for (int it = 0; it < 60; ++it) {
        const cd step = ch.value(l) / ch.derivative(l);
        l -= step;
        if (std::abs(step) < 1e-15 * (1 + std::abs(l))) break;
      }
      if (!(std::abs(ch.value(l)) < 1e-12 * (1 + std::abs(l))) || l.real() < re_min) continue;
      if (std::none_of(roots.begin(), roots.end(), [&](cd r) { return std::abs(r - l) < 1e-8; })) roots.push_back(l);
    }
  std::sort(roots.begin(), roots.end(), [](cd x, cd y) { return x.real() > y.real(); });
  return roots;
}

inline std::vector<std::complex<double>> exact_multipliers(const Characteristic& ch, double T, double re_min,
                                                           double im_max) {
  using cd = std::complex<double>;
  std::vector<cd> mu;
  for (cd l : exact_roots(ch, re_min, im_max)) mu.push_back(std::exp(l * T));
  std::sort(mu.begin(), mu.end(), [](cd x, cd y) { return std::abs(x) > std::abs(y); });
  return mu;
}

// The largest distance from each of `got` to the nearest of `exact` (a matching that ignores the
// order of equal moduli: conjugate pairs).
inline double worst_distance(const std::vector<std::complex<double>>& got,
                             const std::vector<std::complex<double>>& exact) {
  double worst = 0;
  for (const auto& m : got) {
    double best = INFINITY;
    for (const auto& e : exact) best = std::min(best, std::abs(m - e));
    worst = std::max(worst, best);
  }
  return worst;
}

}  // namespace delayspec::test
