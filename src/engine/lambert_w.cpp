#include "delayspec/lambert_w.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "delayspec/multipliers.hpp"
#include "delayspec/errors.hpp"

namespace delayspec {

namespace {

using cd = std::complex<double>;

// Starting guess on branch k: the branch-point series near z = -1/e for k = 0 (+p) and k = -1
// (-p), p = sqrt(2 (e z + 1)); otherwise the asymptotic expansion w ~ L1 - log L1,
// L1 = log z + 2 pi i k (for k = 0 and |z| <= 3, log(1 + z), which is exact to first order at 0).
cd initial_guess(cd z, int k) {
  const cd ez1 = std::numbers::e * z + 1.0;
  auto branch_point_series = [&](double sign) {
    const cd p = sign * std::sqrt(2.0 * ez1);
    return -1.0 + p - p * p / 3.0 + 11.0 / 72.0 * p * p * p;
  };
  if ((k == 0 || k == -1) && std::abs(ez1) < 0.3) return branch_point_series(k == 0 ? 1.0 : -1.0);
  // z real below -1/e: W_0 is complex (upper half plane, scipy's convention on the cut), but
  // log(1 + z) below is real for z in (-1, -1/e), and Halley from a real start stays real: it
  // returned -0.173 for W_0(-0.5) (residual 0.35). Start from the branch-point series, whose
  // p = i sqrt(-2 (e z + 1)) is imaginary.
  if (k == 0 && z.imag() == 0 && ez1.real() < 0 && z.real() > -1) {
    const cd p(0, std::sqrt(-2.0 * ez1.real()));
    return -1.0 + p - p * p / 3.0 + 11.0 / 72.0 * p * p * p;
  }
  if (k == 0 && std::abs(z) <= 3.0) return std::abs(1.0 + z) >= 0.3 ? std::log(1.0 + z) : branch_point_series(1.0);
  const cd L1 = std::log(z) + cd(0, 2 * std::numbers::pi * k);
  return L1 - std::log(L1);
}

}  // namespace

cd lambert_w(cd z, int k) {
  if (!std::isfinite(z.real()) || !std::isfinite(z.imag())) throw BadInput("lambert_w: argument must be finite");
  if (z == cd(0)) {
    if (k == 0) return 0.0;
    throw BadInput("lambert_w: W_k(0) is -infinity for branch k = " + std::to_string(k));
  }
  cd w = initial_guess(z, k);
  for (int it = 0; it < 100; ++it) {
    // Halley: w <- w - f / (f' - f'' f / (2 f')),  f = w e^w - z
    const cd ew = std::exp(w);
    const cd f = w * ew - z;
    const cd wp1 = w + 1.0;
    const cd denom = ew * wp1 - (w + 2.0) * f / (2.0 * wp1);
    const cd step = f / denom;
    w -= step;
    if (std::abs(step) <= 4e-16 * (1 + std::abs(w))) break;
  }
  // Never a value that is not a root: |w e^w - z| within the rounding of e^w (the identity test's
  // bound, 1e-14 |z| (1 + |w|), with a margin of 100).
  if (!(std::abs(w * std::exp(w) - z) <= 1e-12 * std::abs(z) * (1 + std::abs(w))))
    throw NumericalFailure("lambert_w: Halley's iteration did not converge for z = " + format_complex(z) + " on branch " +
                           std::to_string(k));
  return w;
}

std::vector<cd> linear_dde_roots(double a, double b, double tau, int branches) {
  require_finite("a", a);
  require_finite("b", b);
  require_positive("tau", tau);
  if (b == 0) throw BadInput("`b = 0`: the linear DDE has a single root a; Lambert-W roots need b != 0");
  const cd z = b * tau * std::exp(-a * tau);
  std::vector<cd> roots;
  for (int k = -branches; k <= branches; ++k) roots.push_back(a + lambert_w(z, k) / tau);
  std::sort(roots.begin(), roots.end(), [](cd x, cd y) {
    if (x.real() != y.real()) return x.real() > y.real();
    return x.imag() > y.imag();
  });
  return roots;
}

std::vector<cd> linear_dde_multipliers(double a, double b, double tau, double period, int count) {
  require_positive("period", period);
  // Branch k's root has |Im lambda| ~ 2 pi k / tau and decreasing real part: count + 2 branches
  // on each side contain the `count` largest multipliers.
  auto roots = linear_dde_roots(a, b, tau, count + 2);
  std::vector<cd> mu;
  for (cd r : roots) mu.push_back(std::exp(r * period));
  sort_by_modulus(mu);
  mu.resize(std::min<size_t>(mu.size(), count));
  return mu;
}

}  // namespace delayspec
