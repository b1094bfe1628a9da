// Periodic orbits by Newton on the discrete periodic problem (orbit_newton.hpp): the assembled
// Jacobian against finite differences of the residual, quadratic convergence on a smooth
// nonlinear model, agreement with the simulated stable orbit, an unstable orbit simulation cannot
// reach, the sparse LU wrapper, and the failure paths.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include <Eigen/Dense>

#include "delayspec/dense_spectrum.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/model_impact.hpp"
#include "delayspec/model_mathieu.hpp"
#include "delayspec/orbit_newton.hpp"
#include "delayspec/orbit_simulation.hpp"
#include "delayspec/detail/sparse_lu.hpp"

namespace {

using namespace delayspec;

constexpr double kEps = 2.220446049250313e-16;

// A smooth, genuinely nonlinear scalar test model (the built-in nonlinear model, impact, is
// piecewise affine without events, so Newton on it terminates rather than converging
// quadratically):  y' = -alpha y - gamma y^2 + b y(t - tau) + a sin(omega t).
struct QuadraticDelayModel {
  static constexpr int d = 1;
  static constexpr bool has_switching = false;
  static constexpr bool affine_in_state = false;
  static constexpr bool is_linear = false;
  using V = Vec<1>;
  using M = Mat<1>;
  double alpha = 1, gamma = 0.5, b = 0.3, a = 1, omega = 1, delay = 1.7;  // tau / T irrational-ish: theta != 0

  double tau() const { return delay; }
  double period() const { return 2 * std::numbers::pi / omega; }
  V f(int, double t, const V& y, const V& w) const {
    return V(-alpha * y[0] - gamma * y[0] * y[0] + b * w[0] + a * std::sin(omega * t));
  }
  M A(int, double, const V& y, const V&) const { return M(-alpha - 2 * gamma * y[0]); }
  M B(int, double, const V&, const V&) const { return M(b); }
  double H(const V&) const { return 1; }
  V grad_H(const V&) const { return V::Zero(); }
  V initial_state() const { return V(0.2); }
};

template <class Model>
struct MapSetup {
  Model model;
  HistoryGrid grid;
  TrapezoidStepper<Model> stepper;
  StroboscopicMap<Model> map;
  MapSetup(const Model& m, int N, int periods = 1, StepOptions options = {})
      : model(m), grid(make_grid(m.tau(), m.period(), N, periods)), stepper(m, options), map(stepper, grid) {}
};

// Central finite differences of the residual, column by column.
template <class Problem>
Eigen::MatrixXd fd_jacobian(const Problem& problem, const Eigen::VectorXd& x, double delta) {
  const long n = problem.unknowns();
  Eigen::MatrixXd J(n, n);
  for (long j = 0; j < n; ++j) {
    Eigen::VectorXd xp = x, xm = x;
    xp[j] += delta;
    xm[j] -= delta;
    J.col(j) = (problem.residual(xp) - problem.residual(xm)) / (2 * delta);
  }
  return J;
}

ImpactParameters paper_orbit_parameters(double k) {
  ImpactParameters p;  // paper's parameters, tau = T
  p.k = k;
  p.x0 = -0.0566;  // near the period-1 orbit (default scene): simulation reaches it
  p.v0 = 1.0101;
  return p;
}

}  // namespace

// The assembled sparse Jacobian is the derivative of the residual: compared with central
// differences on the smooth model with a fractional delay (theta != 0: all six delayed blocks)
// and a short grid where the delayed indices wrap around the period (K = 11 steps, m = 3).
TEST(OrbitNewton, JacobianEqualsFiniteDifferencesSmoothFractionalDelay) {
  MapSetup<QuadraticDelayModel> s(QuadraticDelayModel{}, 3);
  PeriodicOrbitProblem problem(s.map);
  ASSERT_GT(s.grid.theta, 0.01);
  const long n = problem.unknowns();
  Eigen::VectorXd x = 0.4 * Eigen::VectorXd::Random(n);  // any point: the identity holds everywhere
  Eigen::SparseMatrix<double> J;
  problem.residual(x, &J);
  const Eigen::MatrixXd fd = fd_jacobian(problem, x, 1e-5);
  // Central differences: truncation delta^2 |F'''| / 6 ~ 1e-10 (F''' = O(h gamma) < 1 here) plus
  // rounding eps |F| / delta ~ 1e-11; the entries are O(1).
  EXPECT_LT((Eigen::MatrixXd(J) - fd).lpNorm<Eigen::Infinity>(), 1e-8);
  EXPECT_GT(Eigen::MatrixXd(J).lpNorm<Eigen::Infinity>(), 0.5);  // not trivially zero
}

// Same on the impact model with a fractional delay and a period-2 map, at the orbit perturbed by
// 1e-4 (no node within reach of H = 0 for the FD steps).
TEST(OrbitNewton, JacobianEqualsFiniteDifferencesImpactPeriodTwo) {
  ImpactParameters p;
  p.e = 1.26, p.a = 0.9, p.beta = 29, p.omega = 0.8, p.zeta = 0.01, p.k = 0.12, p.tau = 3.8;
  MapSetup<ImpactModel> s(ImpactModel(p), 6, 2);
  ASSERT_GT(s.grid.theta, 0.01);
  PeriodicOrbitProblem problem(s.map);
  Eigen::VectorXd U = s.map.constant_history(Vec<2>(0.5, 0.5));
  for (int i = 0; i < 20; ++i) U = s.map.apply(U);
  Eigen::VectorXd x = problem.sequence_from_history(U) + 1e-4 * Eigen::VectorXd::Random(problem.unknowns());
  Eigen::SparseMatrix<double> J;
  problem.residual(x, &J);
  const Eigen::MatrixXd fd = fd_jacobian(problem, x, 1e-7);
  // Piecewise affine residual away from H = 0: FD is exact up to rounding eps |F| / delta ~ 1e-8.
  EXPECT_LT((Eigen::MatrixXd(J) - fd).lpNorm<Eigen::Infinity>(), 1e-6);
}

// Quadratic convergence: from the orbit perturbed by 1e-3, each residual satisfies
// r_{i+1} <= C r_i^2 with C = L kappa^2 / 2 (Newton: F(x + s) = F(x) + J s + R with
// |R| <= L/2 |s|^2, |s| <= kappa r), until r reaches rounding. Here L bounds |F''| in the
// inf-norm: only the -gamma y^2 term is nonlinear; differentiating the trapezoid equation twice
// gives |d2 S| <= h gamma (|dS|^2 + |du|^2) / (1 + h/2 (alpha + 2 gamma y)) <= 2 h gamma (1 + O(h))
// per unit direction, so L = 2.5 h gamma leaves 25 % for the O(h) terms. kappa = |J^{-1}|_inf at
// the orbit (dense inverse; J is checked against finite differences above); doubled because the
// iterates are not exactly at the orbit.
TEST(OrbitNewton, ConvergesQuadraticallyFromPerturbedOrbit) {
  QuadraticDelayModel model;
  MapSetup<QuadraticDelayModel> s(model, 40);
  PeriodicOrbitProblem problem(s.map);
  PeriodicOrbit reference = orbit_by_simulation(s.map, s.map.constant_history(model.initial_state()), {1e-14, 5000});
  const Eigen::VectorXd x_star = problem.sequence_from_history(reference.history);
  Eigen::SparseMatrix<double> J;
  problem.residual(x_star, &J);
  const double kappa = 2 * Eigen::MatrixXd(J).inverse().lpNorm<Eigen::Infinity>();
  const double L = 2.5 * s.grid.h * model.gamma;
  const double C = L * kappa * kappa / 2;

  Eigen::VectorXd guess = x_star;
  for (long i = 0; i < guess.size(); ++i) guess[i] += 1e-3 * std::cos(0.7 * static_cast<double>(i));
  PeriodicOrbit orbit = orbit_by_newton(s.map, guess, {1e-15, 20});
  const auto& r = orbit.newton_residuals;
  ASSERT_GE(r.size(), 3u) << "needs at least two Newton steps to show an order";
  EXPECT_LT(C * r[0], 0.1) << "the bound must be far stronger than linear contraction for the test to mean anything";
  const double floor = 100 * kEps * (1 + x_star.lpNorm<Eigen::Infinity>());  // rounding of F
  for (size_t i = 0; i + 1 < r.size(); ++i) {
    if (r[i] < floor) break;
    EXPECT_LE(r[i + 1], C * r[i] * r[i] + floor)
        << "step " << i << ": r = " << r[i] << " -> " << r[i + 1] << ", C = " << C;
  }
  for (double lambda : orbit.newton_step_fractions) EXPECT_EQ(lambda, 1.0) << "near the orbit every step is full";
  EXPECT_LE(orbit.newton_iterations, 4);
}

// Newton reproduces the simulated stable orbit of the paper's system (tau = T, k = 0.2) to 1e-10.
// The simulation settles to |P(U) - U| <= 1e-13 (1 + |U|), so its distance to the fixed point is
// at most that / (1 - |mu_1|) with |mu_1| = 0.63: about 1e-12.
TEST(OrbitNewton, ReproducesSimulatedStableOrbit) {
  ImpactModel model(paper_orbit_parameters(0.2));
  MapSetup<ImpactModel> s(model, 100);
  PeriodicOrbit simulated = orbit_by_simulation(s.map, s.map.constant_history(model.initial_state()), {1e-13, 5000});
  PeriodicOrbitProblem problem(s.map);
  // The guess: one map from the constant initial history (not periodic, residual O(1)).
  const OrbitByNewtonOptions options{1e-14, 30};
  PeriodicOrbit newton =
      orbit_by_newton(s.map, problem.sequence_from_history(s.map.constant_history(model.initial_state())), options);
  EXPECT_GT(newton.newton_residuals.front(), 1e-2);
  EXPECT_LT((newton.history - simulated.history).lpNorm<Eigen::Infinity>(), 1e-10);
  // |P(U) - U| recomputed by the map: each of the K steps leaves a residual <= tolerance (1 + |x|)
  // that the (contracting) map carries to the end, so at most K times that.
  const double scale = 1 + newton.history.lpNorm<Eigen::Infinity>();
  EXPECT_LT(newton.residual, s.grid.K * options.tolerance * scale);
  EXPECT_GT(newton.jacobian_nonzeros, 0);
}

// An orbit simulation cannot reach: with tau = T, the Pyragas term k (v(t - T) - v(t)) vanishes on
// the T-periodic orbit, also in the discrete problem (aligned delay, m = K: w_l = u_l), so the
// orbit is the same for every k; negative gain k = -0.1 destabilises it (a multiplier near -1.9).
// Newton finds it from a guess near it and it equals the stable k = 0.2 orbit found by simulation;
// simulation started near it leaves it.
TEST(OrbitNewton, FindsUnstableOrbitThatSimulationCannot) {
  const StepOptions no_events{EventMode::off, JacobianMode::consistent, 1};  // the exact k-independence above
  ImpactModel stable_model(paper_orbit_parameters(0.2));
  MapSetup<ImpactModel> stable(stable_model, 100, 1, no_events);
  PeriodicOrbit reference =
      orbit_by_simulation(stable.map, stable.map.constant_history(stable_model.initial_state()), {1e-13, 5000});

  ImpactModel model(paper_orbit_parameters(-0.1));
  MapSetup<ImpactModel> s(model, 100, 1, no_events);
  PeriodicOrbitProblem problem(s.map);
  PeriodicOrbit newton =
      orbit_by_newton(s.map, problem.sequence_from_history(s.map.constant_history(model.initial_state())));
  EXPECT_LT((newton.history - reference.history).lpNorm<Eigen::Infinity>(), 1e-10);

  FloquetOptions options;
  options.nev = 2;
  options.solver = FloquetSolver::dense_lapack;
  FloquetResult mu = floquet_multipliers(s.map.monodromy(newton.history), options);
  EXPECT_GT(std::abs(mu.multipliers[0]), 1.5) << "unstable: the leading multiplier is about -1.94 at N = 100";

  // Simulation from the orbit perturbed by 1e-6 leaves it (the perturbation grows like |mu_1|^n)
  // instead of settling; the same perturbation of the stable k = 0.2 orbit settles back.
  const Eigen::VectorXd offset = Eigen::VectorXd::Constant(newton.history.size(), 1e-6);
  EXPECT_THROW(orbit_by_simulation(s.map, newton.history + offset, {1e-12, 300}), NumericalFailure);
  EXPECT_NO_THROW(orbit_by_simulation(stable.map, reference.history + offset, {1e-12, 300}));
}

// A linear model: the residual is affine, so one Newton step from any guess is exact (to rounding).
TEST(OrbitNewton, LinearModelConvergesInOneStep) {
  MathieuParameters p;
  p.b = 0.5;  // strong positive delayed feedback: the zero orbit is unstable (simulation cannot find it)
  MapSetup<MathieuModel> s(MathieuModel(p), 30);
  PeriodicOrbitProblem problem(s.map);
  Eigen::VectorXd guess = Eigen::VectorXd::Random(problem.unknowns());
  PeriodicOrbit orbit = orbit_by_newton(s.map, guess);
  EXPECT_EQ(orbit.newton_iterations, 1);
  // Rounding of the sparse solve: eps times the condition of J times |guess| = O(1).
  EXPECT_LT(orbit.history.lpNorm<Eigen::Infinity>(), 1e-10);
}

// The history of the periodic sequence is the fixed point of the stroboscopic map, including a
// delay longer than the map (M > K: the history wraps the sequence more than once).
TEST(OrbitNewton, HistoryIsFixedPointWhenDelayExceedsPeriod) {
  QuadraticDelayModel model;
  model.delay = 8.1;  // > T = 2 pi
  MapSetup<QuadraticDelayModel> s(model, 30);
  ASSERT_GT(s.grid.M, s.grid.K);
  PeriodicOrbitProblem problem(s.map);
  Eigen::VectorXd guess = problem.sequence_from_history(s.map.constant_history(model.initial_state()));
  PeriodicOrbit orbit = orbit_by_newton(s.map, guess);
  // |P(U) - U| recomputed independently of the Newton residual: rounding of K steps on O(1) states.
  EXPECT_LT(orbit.residual, 1e-13);
}

TEST(OrbitNewton, FailurePathsAreReported) {
  ImpactModel model(paper_orbit_parameters(-0.1));
  MapSetup<ImpactModel> s(model, 50);
  PeriodicOrbitProblem problem(s.map);
  const Eigen::VectorXd guess = problem.sequence_from_history(s.map.constant_history(Vec<2>(0, 0)));
  // One iteration is not enough from an O(1) residual: NumericalFailure naming iterations and residual.
  try {
    orbit_by_newton(s.map, guess, {1e-12, 1});
    FAIL() << "expected NumericalFailure";
  } catch (const NumericalFailure& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("not converged after 1 iterations"), std::string::npos) << what;
    EXPECT_NE(what.find("|F|_inf = "), std::string::npos) << what;
  }
  // A tolerance below rounding: Newton stalls at the rounding floor and says so.
  try {
    orbit_by_newton(s.map, guess, {1e-300, 50});
    FAIL() << "expected NumericalFailure";
  } catch (const NumericalFailure& e) {
    EXPECT_NE(std::string(e.what()).find("stalled"), std::string::npos) << e.what();
  }
  EXPECT_THROW(orbit_by_newton(s.map, guess, {0, 10}), BadInput);
  EXPECT_THROW(orbit_by_newton(s.map, guess, {NAN, 10}), BadInput);
  EXPECT_THROW(orbit_by_newton(s.map, guess, {1e-12, 0}), BadInput);
  EXPECT_THROW(orbit_by_newton(s.map, Eigen::VectorXd::Zero(7), {}), BadInput);
  Eigen::VectorXd nan_guess = guess;
  nan_guess[3] = NAN;
  EXPECT_THROW(orbit_by_newton(s.map, nan_guess, {}), NumericalFailure);
  EXPECT_THROW(problem.residual(Eigen::VectorXd::Zero(5)), BadInput);
}

// The UMFPACK wrapper: a small unsymmetric system with a known solution; a singular matrix and
// wrong sizes are reported.
TEST(SparseLU, SolvesAndReportsSingularity) {
  Eigen::MatrixXd A(3, 3);
  A << 4, 1, 0, 2, 5, 1, 0, 3, 6;
  Eigen::VectorXd x_true(3);
  x_true << 1, -2, 3;
  SparseLU lu(A.sparseView());
  // Backward-stable solve of a well-conditioned 3 x 3 system: error a few eps.
  EXPECT_LT((lu.solve(A * x_true) - x_true).lpNorm<Eigen::Infinity>(), 1e-14);
  EXPECT_GT(lu.reciprocal_condition(), 0.01);
  SparseLU moved = std::move(lu);
  EXPECT_LT((moved.solve(A * x_true) - x_true).lpNorm<Eigen::Infinity>(), 1e-14);

  Eigen::MatrixXd S(2, 2);
  S << 1, 2, 2, 4;
  EXPECT_THROW(SparseLU{S.sparseView()}, NumericalFailure);
  EXPECT_THROW(SparseLU{Eigen::MatrixXd::Ones(2, 3).sparseView()}, BadInput);
  EXPECT_THROW(moved.solve(Eigen::VectorXd::Ones(2)), BadInput);
}

// Named regression against an independent reference: the paper's period-1 orbit at k = 0 (the delay
// does not act, a forced 2-d ODE). Reference multipliers -0.7716866934 +- 0.5093824592i from
// scripts/floquet_results.py k0-reference (RK4, 8000 steps per period, contact boundaries located
// by bisection; stable to 2e-9 between 4000 and 8000 steps): no delayspec code involved. Their
// modulus is exactly exp(-zeta T) (tr A = -2 zeta in both regions, continuous field).
// delayspec with events (default 4 contact sub-steps) at N = 1600 and 3200 (the contact spans
// 12 and 24 steps): errors 4.9e-3 and 1.26e-3, e N^2 = 1.26e4 and 1.29e4 (constant to 5 % over
// N = 400 ... 25600, docs/events.md), so the observed order is within 0.1 of 2 and the Richardson
// value (4 mu_3200 - mu_1600) / 3 is accurate to the remaining O(h^3) + 5 % of the h^2 term,
// measured 5.1e-5: bounded by 2e-4. With one sub-step the order between these N is -0.35 and
// Richardson errs by 7.6e-4 (erratic event-position term). Without events: off by 0.07.
TEST(OrbitNewton, PaperOrbitAtZeroGainMatchesIndependentOdeReference) {
  ImpactModel model(paper_orbit_parameters(0));
  const std::complex<double> reference(-0.7716866934, 0.5093824592);
  std::complex<double> mu[2];
  for (int i = 0; i < 2; ++i) {
    MapSetup<ImpactModel> s(model, 1600 << i);
    PeriodicOrbitProblem problem(s.map);
    Eigen::VectorXd U = s.map.constant_history(model.initial_state());
    for (int j = 0; j < 20; ++j) U = s.map.apply(U);
    PeriodicOrbit orbit = orbit_by_newton(s.map, problem.sequence_from_history(U));
    FloquetOptions options;
    options.nev = 2;
    options.solver = FloquetSolver::spectra;
    FloquetResult result = floquet_multipliers(s.map.monodromy(orbit.history), options);
    mu[i] = result.multipliers[0].imag() > 0 ? result.multipliers[0] : result.multipliers[1];
    // the modulus is much better than the multiplier (measured 2e-5 at N = 1600)
    EXPECT_NEAR(std::abs(mu[i]), std::exp(-model.parameters().zeta * model.period()), 1e-4) << mu[i];
  }
  const double order = std::log2(std::abs(mu[0] - reference) / std::abs(mu[1] - reference));
  EXPECT_NEAR(order, 2.0, 0.1) << mu[0] << " " << mu[1];
  const std::complex<double> richardson = (4.0 * mu[1] - mu[0]) / 3.0;
  EXPECT_LT(std::abs(richardson - reference), 2e-4) << richardson;
}
