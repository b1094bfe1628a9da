// Models with several discrete delays (model.hpp, delay_count) through the engine: the grid's
// taps, the operator, Floquet multipliers, Newton on the periodic problem and Lyapunov exponents.
//
// References the engine did not produce:
//  * the exact characteristic roots of x' = a x + b1 x(t - tau1) + b2 x(t - tau2),
//      lambda = a + b1 exp(-lambda tau1) + b2 exp(-lambda tau2),
//    found here by Newton on that function from a grid of starts; the multipliers of the map over
//    T are exp(lambda T). The trapezoid rule with linear interpolation of the delayed values is
//    second order (design.md 1.2, 1.4): the error of each multiplier falls as N^-2.
//  * the dense matrix of the discrete map, formed column by column from the nonlinear
//    StroboscopicMap (a linear model's map is linear), not from the step maps or the kernels.
//  * the same system written with one delay where the second coefficient is 0 (LinearModel).
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "delayspec/errors.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/lyapunov.hpp"
#include "delayspec/model_analyses.hpp"
#include "delayspec/model_analyses_continuation.hpp"  // the analyses of a model the library does not instantiate
#include "delayspec/model_linear.hpp"
#include "delayspec/orbit_newton.hpp"
#include "delayspec/stroboscopic_map.hpp"
#include "characteristic_roots.hpp"

namespace delayspec {
namespace {

using cd = std::complex<double>;
using test::Characteristic;
using test::exact_multipliers;
using test::worst_distance;

// x' = a x + b1 x(t - tau1) + b2 x(t - tau2) (+ forcing: a cos(2 pi t / T) term, for Newton)
struct TwoDelayScalar {
  static constexpr int d = 1;
  static constexpr int delay_count = 2;
  static constexpr bool has_switching = false, affine_in_state = true, is_linear = true;
  double a = -1, b1 = 0.5, b2 = -0.7, tau1 = 1, tau2 = std::sqrt(2.0), T = 1;
  std::array<double, 2> delays() const { return {tau1, tau2}; }
  double tau() const { return std::max(tau1, tau2); }
  double period() const { return T; }
  Vec<1> f(int, double, const Vec<1>& y, const Vec<2>& z) const { return Vec<1>(a * y[0] + b1 * z[0] + b2 * z[1]); }
  Mat<1> A(int, double, const Vec<1>&, const Vec<2>&) const { return Mat<1>::Constant(a); }
  RectMat<1, 2> B(int, double, const Vec<1>&, const Vec<2>&) const { return RectMat<1, 2>(b1, b2); }
  Vec<1> initial_state() const { return Vec<1>(1); }
};
static_assert(DelayModel<TwoDelayScalar>);

// d = 2 with two delays: x' = y, y' = -c y - x + k1 x(t - tau1) + k2 y(t - tau2) (a delayed
// feedback oscillator with a position and a velocity loop of different latencies).
struct TwoDelayOscillator {
  static constexpr int d = 2;
  static constexpr int delay_count = 2;
  static constexpr bool has_switching = false, affine_in_state = true, is_linear = true;
  double c = 0.1, k1 = 0.3, k2 = -0.2, tau1 = 0.7, tau2 = std::sqrt(1.7), T = 1;
  std::array<double, 2> delays() const { return {tau1, tau2}; }
  double tau() const { return std::max(tau1, tau2); }
  double period() const { return T; }
  Vec<2> f(int, double, const Vec<2>& y, const Vec<4>& z) const {
    return Vec<2>(y[1], -c * y[1] - y[0] + k1 * z[0] + k2 * z[3]);
  }
  Mat<2> A(int, double, const Vec<2>&, const Vec<4>&) const { return (Mat<2>() << 0, 1, -1, -c).finished(); }
  RectMat<2, 4> B(int, double, const Vec<2>&, const Vec<4>&) const {
    RectMat<2, 4> b = RectMat<2, 4>::Zero();
    b(1, 0) = k1;  // d y' / d x(t - tau1)
    b(1, 3) = k2;  // d y' / d y(t - tau2)
    return b;
  }
  Vec<2> initial_state() const { return Vec<2>(1, 0); }
};
static_assert(DelayModel<TwoDelayOscillator>);

// The characteristic function of a linear model with constant coefficients, det(lambda I - A -
// sum_i B_i exp(-lambda tau_i)), and its derivative, for d = 1 and d = 2.
Characteristic characteristic(const TwoDelayScalar& m) {
  return {[m](cd l) { return l - m.a - m.b1 * std::exp(-l * m.tau1) - m.b2 * std::exp(-l * m.tau2); },
          [m](cd l) { return 1.0 + m.b1 * m.tau1 * std::exp(-l * m.tau1) + m.b2 * m.tau2 * std::exp(-l * m.tau2); }};
}
// (l^2 + c l + 1) - k1 e1 - k2 l e2 with e_i = exp(-l tau_i): det of [[l, -1], [1 - k1 e1, l + c - k2 e2]].
Characteristic characteristic(const TwoDelayOscillator& m) {
  return {[m](cd l) {
            const cd e1 = std::exp(-l * m.tau1), e2 = std::exp(-l * m.tau2);
            return l * (l + m.c - m.k2 * e2) + 1.0 - m.k1 * e1;
          },
          [m](cd l) {
            const cd e1 = std::exp(-l * m.tau1), e2 = std::exp(-l * m.tau2);
            return 2.0 * l + m.c - m.k2 * e2 + m.k2 * m.tau2 * l * e2 + m.k1 * m.tau1 * e1;
          }};
}

template <class Model>
StroboscopicMap<Model> map_of(const Model& model, int N) {
  return StroboscopicMap<Model>(TrapezoidStepper<Model>(model), make_grid(delays_of(model), model.period(), N));
}

template <class Model>
Multipliers discrete_multipliers(const Model& model, int N, int nev, FloquetSolver solver = FloquetSolver::arpack) {
  const auto map = map_of(model, N);
  FloquetOptions o;
  o.nev = nev;
  o.solver = solver;
  return floquet_multipliers(map.monodromy(Eigen::VectorXd::Zero(map.dimension())), o).multipliers;
}

TEST(SeveralDelays, GridPlacesEachDelay) {
  // tau2 = sqrt(2) the longest: h = T / round(N T / tau2); tau1 = 1 = K_1 h exactly (aligned)
  const HistoryGrid g = make_grid({1.0, std::sqrt(2.0)}, 1.0, 100);
  ASSERT_EQ(g.delays.size(), 2u);
  EXPECT_EQ(g.steps_per_period, 71);  // round(100 / sqrt 2)
  EXPECT_EQ(g.delays[0].m, 71);
  EXPECT_EQ(g.delays[0].theta, 0.0);
  EXPECT_EQ(g.delays[1].m, g.m);
  EXPECT_DOUBLE_EQ(g.delays[1].theta, g.theta);
  EXPECT_NEAR((g.delays[1].m + g.delays[1].theta) * g.h, std::sqrt(2.0), 1e-14);
  // a delay shorter than one step, or not positive, is bad input naming it
  EXPECT_THROW(make_grid({1e-3, 1.0}, 1.0, 100), BadInput);
  try {
    make_grid({1.0, -0.5}, 1.0, 100);
    FAIL();
  } catch (const BadInput& e) {
    EXPECT_NE(std::string(e.what()).find("delay 2 of 2"), std::string::npos) << e.what();
  }
  // the taps: delay i's rows read its own slot
  const HistoryGrid r = make_grid({0.5, 1.0}, 1.0, 10);  // aligned: m = 5 and 10
  auto slot = [](long i) { return Vec<1>(static_cast<double>(i)); };
  const DelayTap<Vec<2>> tap = r.delay_taps<1, Vec<2>>(0, slot);
  EXPECT_EQ(tap.w0[0], r.M - 5);
  EXPECT_EQ(tap.w0[1], r.M - 10);
  EXPECT_EQ(tap.w1[0], r.M - 4);
}

// One delay's coefficient 0: the same multipliers as the one-delay LinearModel, to rounding (the
// step map's other block is 0; the grid is the same since the longest delay is the model's).
TEST(SeveralDelays, ZeroSecondCoefficientIsTheOneDelayModel) {
  TwoDelayScalar two;
  two.b2 = 0;
  two.tau1 = 1.5;
  two.tau2 = 0.6;
  const LinearModel one({.a = two.a, .b = two.b1, .tau = 1.5, .period = 1});
  const Multipliers mu2 = discrete_multipliers(two, 210, 6, FloquetSolver::dense_lapack);
  const Multipliers mu1 = discrete_multipliers(one, 210, 6, FloquetSolver::dense_lapack);
  ASSERT_EQ(mu1.size(), mu2.size());
  for (size_t i = 0; i < mu1.size(); ++i) EXPECT_LT(std::abs(mu1[i] - mu2[i]), 1e-13) << i;
}

// The operator (step maps through multi_delay_steps, single and blocks) against the dense matrix of
// the map formed from the nonlinear stepper, d = 2, two fractional delays: to 1e-12 (entries O(1),
// a few hundred steps of rounding).
TEST(SeveralDelays, OperatorEqualsTheMapFormedColumnByColumn) {
  const TwoDelayOscillator model;
  const auto map = map_of(model, 40);
  const long n = map.dimension();
  Eigen::MatrixXd dense(n, n);
  for (long j = 0; j < n; ++j) dense.col(j) = map.apply(Eigen::VectorXd::Unit(n, j));
  const auto op = map.monodromy(Eigen::VectorXd::Zero(n));
  EXPECT_LT((op.to_dense() - dense).cwiseAbs().maxCoeff(), 1e-12);
  Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(n, -1, 1), y;
  op.apply(x, y);
  EXPECT_LT((y - dense * x).cwiseAbs().maxCoeff(), 1e-12);
}

// Top multipliers against the exact roots: error ~ N^-2 (order 2.00 +- 0.05 between N = 100 and
// 1600), then Richardson to 1e-10 where tau1 / tau2 is rational (every delay aligned: the error
// has an expansion in even powers of h).
void expect_second_order(const Characteristic& ch, const auto& model, bool aligned) {
  const std::vector<cd> exact = exact_multipliers(ch, model.period(), -12, 60);
  ASSERT_GE(exact.size(), 6u);
  const int nev = 6;
  std::vector<double> errors;
  std::vector<Multipliers> levels;
  for (int N : {100, 200, 400, 800, 1600}) {
    levels.push_back(discrete_multipliers(model, N, nev));
    errors.push_back(worst_distance(levels.back(), exact));
  }
  const double order = std::log2(errors.front() / errors.back()) / 4;
  std::cout << "error of the top " << nev << " multipliers, N = 100 .. 1600:";
  for (double e : errors) std::cout << " " << e;
  std::cout << "; order " << order << "\n";
  EXPECT_NEAR(order, 2.0, 0.05) << "errors " << errors.front() << " .. " << errors.back();
  if (!aligned) return;
  // Two Richardson columns (h^2, h^4) of the last three levels, multiplier by multiplier
  double worst = 0;
  for (int i = 0; i < nev; ++i) {
    const cd x0 = levels[2][i], x1 = levels[3][i], x2 = levels[4][i];
    const cd r01 = (4.0 * x1 - x0) / 3.0, r12 = (4.0 * x2 - x1) / 3.0;
    const cd r = (16.0 * r12 - r01) / 15.0;
    double best = INFINITY;
    for (cd e : exact) best = std::min(best, std::abs(r - e));
    worst = std::max(worst, best);
  }
  std::cout << "Richardson (h^2, h^4) of N = 400, 800, 1600: worst error " << worst << "\n";
  EXPECT_LT(worst, 1e-10);
}

TEST(SeveralDelays, ScalarRationalDelaysSecondOrderAgainstExactRoots) {
  TwoDelayScalar m;
  m.tau1 = 0.5;
  m.tau2 = 1;
  expect_second_order(characteristic(m), m, true);
}

TEST(SeveralDelays, ScalarIrrationalDelaysSecondOrderAgainstExactRoots) {
  const TwoDelayScalar m;  // tau2 = sqrt 2
  expect_second_order(characteristic(m), m, false);
}

TEST(SeveralDelays, OscillatorTwoDelaysAgainstExactRootsAndDense) {
  TwoDelayOscillator m;
  m.tau1 = 0.5;
  m.tau2 = 1;
  expect_second_order(characteristic(m), m, true);
  // Krylov against the dense spectrum of the same discretisation
  const Multipliers krylov = discrete_multipliers(m, 100, 6), dense = discrete_multipliers(m, 100, 6, FloquetSolver::dense_lapack);
  for (size_t i = 0; i < krylov.size(); ++i) {
    double best = INFINITY;
    for (const auto& d : dense) best = std::min(best, std::abs(krylov[i] - d));
    EXPECT_LT(best, 1e-12) << i;
  }
}

// Newton on the periodic problem (the sparse Jacobian's blocks per delay): for a linear model with
// no forcing the orbit is 0 and one Newton step from any sequence lands on it; the Jacobian equals
// a central finite difference of the residual.
TEST(SeveralDelays, PeriodicProblemJacobianIsTheResidualsDerivative) {
  const TwoDelayOscillator model;  // fractional delays
  const auto map = map_of(model, 30);
  const PeriodicOrbitProblem<StroboscopicMap<TwoDelayOscillator>> problem(map);
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(problem.unknowns(), -0.3, 0.8);
  Eigen::SparseMatrix<double> J;
  problem.residual(x, &J);
  const Eigen::MatrixXd dense_J(J);
  double worst = 0;
  for (long j = 0; j < problem.unknowns(); ++j) {
    const double e = 1e-6;
    const Eigen::VectorXd fd = (problem.residual(x + e * Eigen::VectorXd::Unit(x.size(), j)) -
                                problem.residual(x - e * Eigen::VectorXd::Unit(x.size(), j))) / (2 * e);
    worst = std::max(worst, (fd - dense_J.col(j)).cwiseAbs().maxCoeff());
  }
  // The residual is affine in x: the central difference is exact up to rounding, ~1e-16 / 1e-6.
  EXPECT_LT(worst, 1e-8);
}

// Lyapunov exponents of a linear two-delay model are the real parts of its rightmost roots.
TEST(SeveralDelays, LyapunovExponentsAreTheRightmostRealParts) {
  const TwoDelayScalar model;
  const auto map = map_of(model, 400);
  LyapunovOptions o;
  o.exponents = 2;
  o.transient = 50;
  o.periods = 400;
  const LyapunovResult r = lyapunov_exponents(map, map.constant_history(model.initial_state()), o);
  const std::vector<cd> mu = exact_multipliers(characteristic(model), 1, -12, 60);
  std::vector<double> re;
  for (cd m : mu) re.push_back(std::log(std::abs(m)));
  // the leading exponent to the average's reported error (3 sigma) plus the discretisation's
  // (log |mu_1| at N = 400: second order, ~1e-5; 1e-4 covers it)
  EXPECT_NEAR(r.per_period[0], re[0], 3 * r.error_per_period[0] + 1e-4)
      << re[0] << " +- " << r.error_per_period[0];
}

// The eigenvalues of the Jacobian of `map` at U by central differences with step e: column j is
// (P(U + e e_j) - P(U - e e_j)) / 2e, from the nonlinear map alone (no step map is used).
template <class Model>
std::vector<cd> difference_jacobian_eigenvalues(const StroboscopicMap<Model>& map, const Eigen::VectorXd& U, double e) {
  const long n = U.size();
  Eigen::MatrixXd J(n, n);
  for (long j = 0; j < n; ++j)
    J.col(j) = (map.apply(U + e * Eigen::VectorXd::Unit(n, j)) - map.apply(U - e * Eigen::VectorXd::Unit(n, j))) / (2 * e);
  const Eigen::VectorXcd ev = J.eigenvalues();
  return std::vector<cd>(ev.data(), ev.data() + ev.size());
}

// A forced Duffing oscillator under two delayed loops (data/scenes/equations_two_delays.toml's
// equation at its values): nonlinear, so Newton, shooting and the linearisation at the orbit run.
struct TwoDelayDuffing {
  static constexpr int d = 2;
  static constexpr int delay_count = 2;
  static constexpr bool has_switching = false, affine_in_state = false, is_linear = false;
  double zeta = 0.1, alpha = 0.2, F = 0.4, Omega = 1.1, kp = 0.2, kv = 0.1, tp = 1, tv = std::sqrt(2.0);
  std::array<double, 2> delays() const { return {tp, tv}; }
  double tau() const { return std::max(tp, tv); }
  double period() const { return 2 * M_PI / Omega; }
  Vec<2> f(int, double t, const Vec<2>& y, const Vec<4>& z) const {
    return Vec<2>(y[1], -2 * zeta * y[1] - y[0] - alpha * y[0] * y[0] * y[0] + F * std::cos(Omega * t) - kp * z[0] -
                            kv * z[3]);
  }
  Mat<2> A(int, double, const Vec<2>& y, const Vec<4>&) const {
    return (Mat<2>() << 0, 1, -1 - 3 * alpha * y[0] * y[0], -2 * zeta).finished();
  }
  RectMat<2, 4> B(int, double, const Vec<2>&, const Vec<4>&) const {
    RectMat<2, 4> b = RectMat<2, 4>::Zero();
    b(1, 0) = -kp;  // by x(t - tp)
    b(1, 3) = -kv;  // by v(t - tv)
    return b;
  }
  Vec<2> initial_state() const { return Vec<2>(0, 0); }
};
static_assert(DelayModel<TwoDelayDuffing>);

// The orbit by Newton on the periodic problem and by shooting agree; its multipliers (the
// operator's step maps, through the analyses every command uses) equal the eigenvalues of the
// map's Jacobian formed by central differences of the nonlinear map at the orbit, which never
// sees a step map: to 1e-7, the difference quotient's error (h^2 f''' ~ 1e-10 with h = 1e-5,
// plus rounding eps / h ~ 1e-11, amplified by the eigenproblem's conditioning).
TEST(SeveralDelays, NonlinearOrbitMultipliersEqualTheMapsFiniteDifferenceJacobian) {
  const TwoDelayDuffing model;
  const ModelAnalysesFor<TwoDelayDuffing> typed(model);
  const ModelAnalyses& analyses = typed;
  MapSettings settings;
  settings.N = 40;
  OrbitSettings by_newton, by_shooting;
  by_newton.method = OrbitMethod::newton;
  by_shooting.method = OrbitMethod::shooting;
  const LinearisedOrbit newton = analyses.linearised_orbit(settings, by_newton);
  const LinearisedOrbit shooting = analyses.linearised_orbit(settings, by_shooting);
  EXPECT_LT((newton.orbit.history - shooting.orbit.history).cwiseAbs().maxCoeff(), 1e-9);
  FloquetOptions o;
  o.nev = 6;
  o.solver = FloquetSolver::dense_lapack;
  const Multipliers mu = floquet_multipliers(*newton.monodromy, o).multipliers;

  const StroboscopicMap<TwoDelayDuffing> map(TrapezoidStepper<TwoDelayDuffing>(model), analyses.grid(settings));
  const std::vector<cd> fd = difference_jacobian_eigenvalues(map, newton.orbit.history, 1e-5);
  EXPECT_GT(std::abs(mu[0]), 0.5);  // a non-trivial leading pair
  EXPECT_LT(worst_distance(mu, fd), 1e-7);
}

// The Lyapunov exponents of the stable forced orbit are log |mu| of its leading multipliers.
TEST(SeveralDelays, NonlinearLyapunovExponentsAreTheOrbitsLeadingMultipliers) {
  const TwoDelayDuffing model;
  const ModelAnalysesFor<TwoDelayDuffing> typed(model);
  const ModelAnalyses& analyses = typed;
  MapSettings settings;
  settings.N = 100;
  const LinearisedOrbit at = analyses.linearised_orbit(settings, OrbitSettings{});
  FloquetOptions o;
  o.nev = 2;
  const Multipliers mu = floquet_multipliers(*at.monodromy, o).multipliers;
  LyapunovOptions l;
  l.exponents = 2;
  l.transient = 200;
  l.periods = 400;
  const LyapunovResult r = analyses.lyapunov(settings, l);
  // a complex pair: both exponents are log |mu_1|, to the averages' error (reported)
  EXPECT_NEAR(r.per_period[0], std::log(std::abs(mu[0])), 3 * r.error_per_period[0] + 1e-3);
  EXPECT_NEAR(r.per_period[1], std::log(std::abs(mu[1])), 3 * r.error_per_period[1] + 1e-3);
}

// A time window with two delays: x' = a_j x + b1 x(t - tau1) + b2 x(t - tau2), a_1 inside the
// window sin(2 pi t / T) > c and a_2 outside (time switches, model.hpp). With tau1 = tau2 the two
// delayed terms are one, (b1 + b2) x(t - tau): the same multipliers as that one-delay model, to
// rounding (an identity; the split steps of time_switch_step carry the stacked taps).
template <int NT>
struct WindowedScalar {
  static constexpr int d = 1;
  static constexpr int delay_count = NT;
  static constexpr bool has_switching = false, has_time_switches = true, affine_in_state = true, is_linear = true;
  double a1 = -2, a2 = 0.5, b1 = 0.4, b2 = -0.3, c = 0.3, tau1 = 1.25, tau2 = 1.25, T = 1;
  std::array<double, NT> delays() const {
    if constexpr (NT == 2) return {tau1, tau2};
    else return {tau1};
  }
  double tau() const { return std::max(tau1, tau2); }
  double period() const { return T; }
  double a(int j) const { return j == 1 ? a1 : a2; }
  Vec<1> f(int j, double, const Vec<1>& y, const Vec<NT>& z) const {
    return Vec<1>(a(j) * y[0] + (NT == 2 ? b1 * z[0] + b2 * z[NT - 1] : (b1 + b2) * z[0]));
  }
  Mat<1> A(int j, double, const Vec<1>&, const Vec<NT>&) const { return Mat<1>::Constant(a(j)); }
  RectMat<1, NT> B(int, double, const Vec<1>&, const Vec<NT>&) const {
    RectMat<1, NT> b;
    if constexpr (NT == 2) b << b1, b2;
    else b << b1 + b2;
    return b;
  }
  Vec<1> initial_state() const { return Vec<1>(1); }
  int time_segment(double t) const { return std::sin(2 * M_PI * t / T) > c ? 1 : 2; }
  double next_time_switch(double t0, double t1) const {  // the window's ends in (t0, t1), to adjacent doubles
    const double ends[2] = {std::asin(c) / (2 * M_PI) * T, (0.5 - std::asin(c) / (2 * M_PI)) * T};
    double best = t1;
    for (double base = std::floor(t0 / T) * T; base < t1; base += T)
      for (double e : ends)
        if (base + e > t0 && base + e < best) best = base + e;
    return best;
  }
};

TEST(SeveralDelays, TimeWindowWithTwoEqualDelaysIsTheOneDelayModel) {
  const WindowedScalar<2> two;
  const WindowedScalar<1> one;
  static_assert(DelayModel<WindowedScalar<2>> && TimeSwitchedModel<WindowedScalar<2>>);
  const Multipliers mu2 = discrete_multipliers(two, 80, 6, FloquetSolver::dense_lapack);
  const Multipliers mu1 = discrete_multipliers(one, 80, 6, FloquetSolver::dense_lapack);
  ASSERT_EQ(mu1.size(), mu2.size());
  for (size_t i = 0; i < mu1.size(); ++i) EXPECT_LT(std::abs(mu1[i] - mu2[i]), 1e-13) << i;
}

// The impact model of the paper with its feedback over two delays of different lengths,
// k1 (v(t - T) - v) + k2 (v(t - T/2) - v), at e = 0.9: a stable orbit with one contact per map
// (located events, state switching with several delays).
struct TwoDelayImpact {
  static constexpr int d = 2;
  static constexpr int delay_count = 2;
  static constexpr bool has_switching = true, affine_in_state = true, is_linear = false;
  double zeta = 0.01, e = 0.9, a = 0.7, beta = 28, omega = 0.802, k1 = 0.4, k2 = 0.15;
  double period() const { return 2 * M_PI / omega; }
  std::array<double, 2> delays() const { return {period(), 0.5 * period()}; }
  double tau() const { return period(); }
  Vec<2> f(int j, double t, const Vec<2>& y, const Vec<4>& z) const {
    const double contact = j == 1 ? beta * (y[0] - e) : 0.0;
    return Vec<2>(y[1], a * omega * omega * std::sin(omega * t) + k1 * (z[1] - y[1]) + k2 * (z[3] - y[1]) -
                            2 * zeta * y[1] - y[0] - contact);
  }
  Mat<2> A(int j, double, const Vec<2>&, const Vec<4>&) const {
    return (Mat<2>() << 0, 1, -1 - (j == 1 ? beta : 0.0), -k1 - k2 - 2 * zeta).finished();
  }
  RectMat<2, 4> B(int, double, const Vec<2>&, const Vec<4>&) const {
    RectMat<2, 4> b = RectMat<2, 4>::Zero();
    b(1, 1) = k1;
    b(1, 3) = k2;
    return b;
  }
  Vec<2> f_t(int, double t, const Vec<2>&, const Vec<4>&) const {
    return Vec<2>(0, a * omega * omega * omega * std::cos(omega * t));
  }
  Vec<2> f_tt(int, double t, const Vec<2>&, const Vec<4>&) const {
    return Vec<2>(0, -a * omega * omega * omega * omega * std::sin(omega * t));
  }
  double H(const Vec<2>& y) const { return y[0] - e; }
  Vec<2> grad_H(const Vec<2>&) const { return Vec<2>(1, 0); }
  Vec<2> initial_state() const { return Vec<2>(0, 0); }
};
static_assert(DelayModel<TwoDelayImpact>);

// Its multipliers (the event steps' maps, blocks per delay) against the eigenvalues of the map's
// central-difference Jacobian at the orbit, which sees only the located trajectory: the map is
// smooth near an orbit with transversal contacts, so the difference quotient has its usual
// error, ~1e-10 at h = 1e-6 with event times located to ~1e-15; 1e-7 leaves room for the
// eigenproblem's conditioning.
TEST(SeveralDelays, ImpactingOrbitMultipliersEqualTheMapsFiniteDifferenceJacobian) {
  const TwoDelayImpact model;
  const ModelAnalysesFor<TwoDelayImpact> typed(model);
  const ModelAnalyses& analyses = typed;
  MapSettings settings;
  settings.N = 60;
  const LinearisedOrbit at = analyses.linearised_orbit(settings, OrbitSettings{});
  ASSERT_GE(at.contacts.contacts, 1) << "the orbit must touch H = 0 for this test";
  FloquetOptions o;
  o.nev = 6;
  o.solver = FloquetSolver::dense_lapack;
  const Multipliers mu = floquet_multipliers(*at.monodromy, o).multipliers;
  const StroboscopicMap<TwoDelayImpact> map(TrapezoidStepper<TwoDelayImpact>(model), analyses.grid(settings));
  const std::vector<cd> fd = difference_jacobian_eigenvalues(map, at.orbit.history, 1e-6);
  EXPECT_GT(std::abs(mu[0]), 0.5);
  EXPECT_LT(worst_distance(mu, fd), 1e-7);
}

}  // namespace
}  // namespace delayspec
