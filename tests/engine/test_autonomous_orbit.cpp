// Periodic orbits of unknown period (autonomous_orbit.hpp), on an oscillator whose orbit, its
// discretisation and its multipliers are known in closed form:
//
//   z' = (1 + i omega) z - |z|^2 z + k (|z(t - tau)|^2 - 1) z,   z = x + i y,
//
// whose circle |z| = 1 is a periodic orbit of period 2 pi / omega for every tau and k (the delayed
// term vanishes on it). The field is radial but for the rotation, so the discrete orbit is a
// circle too, turned by the trapezoid rule by alpha = 2 atan(omega T h / 2) per step (T h the step
// in time): with K steps, exactly T_K = (2 K / omega) tan(pi / K), an error (2 pi / omega) pi^2 /
// (3 K^2) + O(K^-4), second order. Its radius r0 is not 1: the fractional delay's tap
// interpolates between two nodes alpha apart, a chord of length c r0, c^2 = 1 - 2 theta (1 -
// theta) (1 - cos alpha), so 1 - r0^2 + k (c^2 r0^2 - 1) = 0: r0^2 = (1 - k) / (1 - k c^2), again
// 1 + O(h^2). Linearised in the rotating frame,
// r = 1 + rho, the phase is neutral (the trivial multiplier 1) and rho' = -2 rho + 2 k
// rho(t - tau): the other multipliers are exp(lambda T) with lambda = -2 + W(2 k tau e^{2 tau})
// / tau (Lambert W, lambert_w.hpp). For k > 1 a real root is positive: the circle is unstable.
#include <cmath>
#include <complex>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

#include "delayspec/autonomous_orbit.hpp"
#include "delayspec/autonomous_shooting.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/lambert_w.hpp"
#include "delayspec/model_mackey_glass.hpp"
#include "delayspec/richardson.hpp"
#include "circle_oscillator.hpp"

namespace delayspec {
namespace {

AutonomousOrbit orbit_of(const Circle& c, int N, double guess = 1.1, int guess_periods = 10) {
  AutonomousOrbitOptions o;
  o.period_guess = guess;
  o.N = N;
  o.guess_periods = guess_periods;
  return find_autonomous_orbit(c, o);
}

TEST(AutonomousOrbit, PeriodIsTheDiscreteClosedFormAndConvergesAtOrderTwo) {
  const Circle c;
  std::vector<double> h, errors;
  std::vector<std::complex<double>> periods;
  for (int N : {20, 40, 80, 160}) {
    const AutonomousOrbit orbit = orbit_of(c, N);
    const int K = orbit.grid.K;
    // Newton stops at |F| <= 1e-12 (1 + |x|) = 2.2e-12: the period to a few times that (dF/dT is
    // O(1) per period), the radius to that over the radial contraction per step, 2 T / K
    EXPECT_NEAR(orbit.period, 2 * K * std::tan(M_PI / K) / c.omega, 1e-11) << "K = " << K;
    const double radius_tolerance = 2 * 2.2e-12 / (2 * orbit.period / K);
    const double alpha = 2 * std::atan(c.omega * orbit.period / (2 * K)), theta = orbit.grid.theta;
    const double c2 = 1 - 2 * theta * (1 - theta) * (1 - std::cos(alpha));
    const double r0 = std::sqrt((1 - c.k) / (1 - c.k * c2));
    for (long l = 0; l < K; ++l) EXPECT_NEAR(orbit.sequence.segment<2>(2 * l).norm(), r0, radius_tolerance);
    h.push_back(1.0 / K);
    errors.push_back(std::abs(orbit.period - 1));
    periods.emplace_back(orbit.period);
  }
  for (size_t i = 1; i < errors.size(); ++i) {
    // K = round(N T_guess / tau) doubles with N up to rounding: the order from the steps themselves
    const double order = std::log(errors[i - 1] / errors[i]) / std::log(h[i - 1] / h[i]);
    EXPECT_NEAR(order, 2.0, 0.05) << "between h = " << h[i - 1] << " and " << h[i];
  }
  // The error's expansion is in h^2, h^4 (tan): Richardson on four levels to 1e-9 and better
  const Extrapolation e = richardson_extrapolate(h, periods);
  EXPECT_NEAR(e.value.real(), 1.0, 1e-9) << e.note;
}

TEST(AutonomousOrbit, MultipliersAreTheTrivialOneAndTheRotatingFramesRoots) {
  const Circle c;
  std::vector<double> trivial_errors;
  for (int N : {100, 200, 400}) {
    const AutonomousOrbit orbit = orbit_of(c, N);
    const auto map = autonomous_orbit_map(c, orbit);
    FloquetOptions fo;
    fo.nev = 4;
    const FloquetResult r = floquet_multipliers(map.monodromy(orbit.history), fo);
    // the trivial one: nearest 1
    size_t t = 0;
    for (size_t i = 1; i < r.multipliers.size(); ++i)
      if (std::abs(r.multipliers[i] - 1.0) < std::abs(r.multipliers[t] - 1.0)) t = i;
    trivial_errors.push_back(std::abs(r.multipliers[t] - 1.0));
    // the others against exp(lambda T) of rho' = -2 rho + 2 k rho(t - tau): second order, 1e-3 at N = 100
    const std::vector<std::complex<double>> roots = linear_dde_roots(-2, 2 * c.k, c.delay, 8);
    for (size_t i = 0; i < r.multipliers.size(); ++i) {
      if (i == t) continue;
      double best = INFINITY;
      for (auto l : roots) best = std::min(best, std::abs(r.multipliers[i] - std::exp(l * orbit.period)));
      EXPECT_LT(best, 2e-3 * 100.0 * 100.0 / (N * N)) << r.multipliers[i];
    }
  }
  // The field commutes with rotations, and so does the discrete problem: the rotation of the
  // discrete orbit is a discrete orbit, so the trivial multiplier is 1 to the eigensolver's
  // accuracy here (tol 1e-12 relative; 1e-9 leaves room for the pair's conditioning). Without
  // that symmetry it is 1 to rounding as well (Mackey-Glass below).
  for (double e : trivial_errors) EXPECT_LT(e, 1e-9);
}

// Mackey-Glass (beta 0.2, gamma 0.1, n 10) at tau = 8, past its Hopf point (tau_H = 4.708): a
// stable orbit of unknown period. No closed form; the discretisation's order is the check: the
// period's successive differences fall as h^2. The trivial multiplier does not tend to 1 at
// order 2 (as issue 35 expected) but is 1 to rounding at every N: the trapezoid step of an
// autonomous system is the exact flow of a modified autonomous field up to terms exponentially
// small in 1 / h (backward error analysis), and a modified autonomous field's orbit has the
// exact multiplier 1. So |mu - 1| far above rounding flags an orbit not converged, or a model
// that is not smooth.
TEST(AutonomousOrbit, MackeyGlassPeriodConvergesAtOrderTwoAndTheTrivialMultiplierIsOne) {
  MackeyGlassParameters p;
  p.tau = p.period = 8;
  p.x0 = 1.1;
  const MackeyGlassModel model(p);
  std::vector<double> periods, trivial, h;
  for (int N : {50, 100, 200, 400, 3200}) {
    AutonomousOrbitOptions o;
    o.period_guess = 20;
    o.N = N;
    o.guess_periods = 40;
    const AutonomousOrbit orbit = find_autonomous_orbit(model, o);
    const auto map = autonomous_orbit_map(model, orbit);
    FloquetOptions fo;
    fo.nev = 3;
    const FloquetResult r = floquet_multipliers(map.monodromy(orbit.history), fo);
    double nearest = INFINITY;
    for (auto mu : r.multipliers) nearest = std::min(nearest, std::abs(mu - 1.0));
    periods.push_back(orbit.period);
    trivial.push_back(nearest);
    h.push_back(1.0 / orbit.grid.K);
    std::cout << "N = " << N << ": T = " << orbit.period << ", |mu_trivial - 1| = " << nearest << "\n";
  }
  // The error against N = 3200 (whose own error is (50 / 3200)^2 = 2.4e-4 of the first one's) over
  // the range N = 50 .. 400: the fractional delay's weight changes with K, so successive ratios
  // wander (1.8 to 2.2 here): the h^2 coefficient C(theta) differs between the levels, and the
  // order over h ratio 8 is 2 + log(C_50 / C_400) / log 8; C within +-20 % gives 2.00 +- 0.1.
  const double e_first = std::abs(periods[0] - periods[4]), e_last = std::abs(periods[3] - periods[4]);
  EXPECT_NEAR(std::log(e_first / e_last) / std::log(h[0] / h[3]), 2.0, 0.1) << e_first << " " << e_last;
  // Krylov's tolerance 1e-12 relative, times the pair's conditioning: 1e-10
  for (double e : trivial) EXPECT_LT(e, 1e-10);
}

// Pyragas control of the subcritical Hopf normal form (Fiedler et al., PRL 98, 114101, 2007):
//   z' = (lam + i) z + (1 + i gam) |z|^2 z + b0 e^{i beta} (z(t - tau) - z(t)),
// the orbit |z|^2 = -lam of period T = 2 pi / (1 - gam lam), tau = T. Uncontrolled (b0 = 0) its
// radial exponent is -2 lam: the multiplier exp(-2 lam T) > 1, found although unstable; with
// b0 = 0.3, beta = pi / 4 the control makes it stable.
struct PyragasNormalForm {
  static constexpr int d = 2;
  static constexpr bool has_switching = false, affine_in_state = false, is_linear = false, autonomous = true;
  double lam = -0.005, gam = -10, b0 = 0, beta = M_PI / 4;
  double tau() const { return 2 * M_PI / (1 - gam * lam); }
  double period() const { return tau(); }
  Vec<2> f(int, double, const Vec<2>& y, const Vec<2>& w) const {
    const double r2 = y.squaredNorm(), c = b0 * std::cos(beta), s = b0 * std::sin(beta);
    const Vec<2> dz = w - y;
    return Vec<2>(lam * y[0] - y[1] + r2 * (y[0] - gam * y[1]) + c * dz[0] - s * dz[1],
                  y[0] + lam * y[1] + r2 * (gam * y[0] + y[1]) + s * dz[0] + c * dz[1]);
  }
  Mat<2> A(int, double, const Vec<2>& y, const Vec<2>&) const {
    const double r2 = y.squaredNorm(), c = b0 * std::cos(beta), s = b0 * std::sin(beta);
    Mat<2> a;
    a << lam + r2 + 2 * y[0] * (y[0] - gam * y[1]) - c, -1 - gam * r2 + 2 * y[1] * (y[0] - gam * y[1]) + s,
        1 + gam * r2 + 2 * y[0] * (gam * y[0] + y[1]) - s, lam + r2 + 2 * y[1] * (gam * y[0] + y[1]) - c;
    return a;
  }
  Mat<2> B(int, double, const Vec<2>&, const Vec<2>&) const {
    const double c = b0 * std::cos(beta), s = b0 * std::sin(beta);
    return (Mat<2>() << c, -s, s, c).finished();
  }
  Vec<2> initial_state() const { return Vec<2>(std::sqrt(-lam), 0); }
};

TEST(AutonomousOrbit, PyragasControlStabilisesTheOrbitItLeavesInPlace) {
  PyragasNormalForm model;
  const double T_exact = model.tau();
  std::vector<double> period_errors, multiplier_errors;
  for (int N : {100, 200, 400}) {
    AutonomousOrbitOptions o;
    o.period_guess = 6.6;
    o.N = N;
    o.guess_periods = 1;
    const AutonomousOrbit orbit = find_autonomous_orbit(model, o);
    FloquetOptions fo;
    fo.nev = 3;
    const FloquetResult r = floquet_multipliers(autonomous_orbit_map(model, orbit).monodromy(orbit.history), fo);
    period_errors.push_back(std::abs(orbit.period - T_exact));
    multiplier_errors.push_back(std::abs(r.multipliers[0] - std::exp(-2 * model.lam * T_exact)));
  }
  // second order over h ratio 4, through the fractional delay's wandering coefficient (+-0.2)
  EXPECT_NEAR(std::log2(period_errors[0] / period_errors[2]) / 2, 2.0, 0.2);
  EXPECT_NEAR(std::log2(multiplier_errors[0] / multiplier_errors[2]) / 2, 2.0, 0.2);
  model.b0 = 0.3;  // controlled: the same orbit (the control vanishes on it), now stable
  AutonomousOrbitOptions o;
  o.period_guess = 6.6;
  o.N = 200;
  o.guess_periods = 1;
  const AutonomousOrbit orbit = find_autonomous_orbit(model, o);
  EXPECT_NEAR(orbit.period, T_exact, 1e-4);  // the period's error at N = 200 (4e-5 measured)
  FloquetOptions fo;
  fo.nev = 3;
  const FloquetResult r = floquet_multipliers(autonomous_orbit_map(model, orbit).monodromy(orbit.history), fo);
  // the trivial multiplier and then the leading other one, inside the unit circle
  EXPECT_LT(std::abs(r.multipliers[0] - 1.0), 1e-9);
  EXPECT_LT(std::abs(r.multipliers[1]), 0.95);
}

TEST(AutonomousOrbit, AnUnstableOrbitIsFound) {
  Circle c;
  c.k = 1.5;  // lambda = -2 + 3 e^{-lambda tau} has a positive real root: the circle repels
  c.start = Vec<2>(1.02, 0);
  const AutonomousOrbit orbit = orbit_of(c, 100, 1.05, 1);  // one simulated period: still near it
  EXPECT_NEAR(orbit.period, 2 * orbit.grid.K * std::tan(M_PI / orbit.grid.K) / c.omega, 1e-12);
  const auto map = autonomous_orbit_map(c, orbit);
  FloquetOptions fo;
  fo.nev = 3;
  const FloquetResult r = floquet_multipliers(map.monodromy(orbit.history), fo);
  EXPECT_GT(std::abs(r.multipliers[0]), 1.1);  // the unstable one, exp(lambda T) with lambda > 0
}

TEST(AutonomousOrbit, NoOrbitNearTheGuessIsANumericalFailureNamingTheResidual) {
  Circle c;
  c.start = Vec<2>(0, 0);  // the equilibrium: the simulated guess is the zero sequence
  try {
    orbit_of(c, 50);
    FAIL() << "the zero sequence is no orbit";
  } catch (const NumericalFailure& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no periodic orbit near the guess"), std::string::npos) << what;
    EXPECT_NE(what.find("residual"), std::string::npos) << what;
  }
  EXPECT_THROW(orbit_of(c, 50, -1.0), BadInput);
}

// Nested shooting on (U, T) (autonomous_shooting.hpp) solves the same discrete problem as
// sparse-LU Newton on the whole period (the same K). Newton's test bounds the residual of each of
// the K steps; at its default 1e-12 (1 + |x|) those add up over K = 2500 steps to a period error
// of 7e-10 (measured; shooting's test bounds P(U) - U over the whole period, the accurate one).
// At 1e-13 Newton converges to rounding (residual 4e-16) and the two periods agree to 2e-14
// (measured): 1e-11 asserted.
TEST(AutonomousOrbit, ShootingAndNewtonFindTheSameOrbit) {
  MackeyGlassParameters p;
  p.tau = p.period = 8;
  p.x0 = 1.1;
  const MackeyGlassModel model(p);
  AutonomousOrbitOptions o;
  o.period_guess = 25;
  o.N = 800;
  o.guess_periods = 40;
  o.newton.tolerance = 1e-13;
  const AutonomousOrbit newton = find_autonomous_orbit(model, o);
  const AutonomousOrbit shooting = find_autonomous_orbit_by_shooting(model, o);
  ASSERT_EQ(newton.grid.K, shooting.grid.K);
  EXPECT_NEAR(shooting.period, newton.period, 1e-11);
  // The same orbit up to the time shift each phase condition picks (not a whole number of steps):
  // the extremes over the nodes agree to the sampling's O(h^2) (h = 1 / K, K = 2577: ~1e-7), the
  // multipliers (shift-invariant) to the eigensolver's tolerance
  auto extremes = [](const AutonomousOrbit& a) {
    return std::pair(a.sequence.maxCoeff(), a.sequence.minCoeff());
  };
  EXPECT_NEAR(extremes(shooting).first, extremes(newton).first, 1e-6);
  EXPECT_NEAR(extremes(shooting).second, extremes(newton).second, 1e-6);
  FloquetOptions fo;
  fo.nev = 4;
  const auto mu_newton = floquet_multipliers(autonomous_orbit_map(model, newton).monodromy(newton.history), fo);
  const auto mu_shooting = floquet_multipliers(autonomous_orbit_map(model, shooting).monodromy(shooting.history), fo);
  for (size_t i = 0; i < 4; ++i) EXPECT_NEAR(std::abs(mu_shooting.multipliers[i] - mu_newton.multipliers[i]), 0, 1e-8);
}

// An unstable orbit by shooting: the circle oscillator at k = 1.5 (test above), period and
// radius the discrete closed form's.
TEST(AutonomousOrbit, ShootingFindsAnUnstableOrbit) {
  Circle c;
  c.k = 1.5;
  AutonomousOrbitOptions o;
  o.period_guess = 1.05;
  o.N = 400;
  o.guess_periods = 1;  // one simulated period from near the circle: still near it
  c.start = Vec<2>(1.02, 0);
  const AutonomousOrbit orbit = find_autonomous_orbit_by_shooting(c, o);
  const int K = orbit.grid.K;
  EXPECT_NEAR(orbit.period, 2 * K * std::tan(M_PI / K) / c.omega, 1e-11);
  FloquetOptions fo;
  fo.nev = 3;
  const FloquetResult r = floquet_multipliers(autonomous_orbit_map(c, orbit).monodromy(orbit.history), fo);
  EXPECT_GT(std::abs(r.multipliers[0]), 1.1);
}

}  // namespace
}  // namespace delayspec
