// Newton-Krylov shooting with nested iteration (orbit_shooting.hpp) and its GMRES (gmres.hpp):
// GMRES against a dense solve; the level rule; the orbit against sparse-LU Newton and simulation
// (orbits found by different algorithms on different unknowns) on aligned and fractional delays,
// period 1 and 2, stable and unstable; the Newton step counts of the nested start; the
// linearisation handed back; the failure paths.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include <Eigen/Dense>

#include "cli_test_support.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/gmres.hpp"
#include "delayspec/model_impact.hpp"
#include "delayspec/orbit_newton.hpp"
#include "delayspec/orbit_shooting.hpp"
#include "delayspec/orbit_simulation.hpp"
#include "delayspec_test_paths.hpp"
#include <nlohmann/json.hpp>

namespace {

using namespace delayspec;
using delayspec::testing::CliResult;
using delayspec::testing::run;

struct ImpactSetup {
  ImpactModel model;
  HistoryGrid grid;
  TrapezoidStepper<ImpactModel> stepper;
  StroboscopicMap<ImpactModel> map;
  ImpactSetup(const ImpactParameters& p, int N, int periods = 1)
      : model(p), grid(make_grid(model.tau(), model.period(), N, periods)), stepper(model), map(stepper, grid) {}
};

ImpactParameters paper(double k) {  // the paper's system at tau = T, initial history near the orbit
  ImpactParameters p;
  p.k = k;
  p.x0 = -0.0566;
  p.v0 = 1.0101;
  return p;
}

ImpactParameters pwsdde_period_two() {  // data/scenes/pwsdde-period2.toml: fractional delay, period 2
  ImpactParameters p;
  p.zeta = 0.01, p.e = 1.26, p.a = 0.9, p.beta = 29, p.omega = 0.8, p.k = 0.12, p.tau = 3.8;
  return p;
}

// The orbit by sparse-LU Newton at N from `guess_periods` simulated maps (the `orbit = newton` path).
PeriodicOrbit sparse_newton(const ImpactSetup& s, long guess_periods) {
  Eigen::VectorXd U = s.map.constant_history(s.model.initial_state());
  for (long i = 0; i < guess_periods; ++i) U = s.map.apply(U);
  return orbit_by_newton(s.map, PeriodicOrbitProblem(s.map).sequence_from_history(U), {1e-13, 30});
}

double relative_distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).lpNorm<Eigen::Infinity>() / b.lpNorm<Eigen::Infinity>();
}

}  // namespace

// GMRES on a nonsymmetric, well-conditioned system (I + a random 0.3-scaled matrix) with a restart
// shorter than n: the solution equals the dense LU solve to the requested tolerance times the
// condition number (< 10 here), and the reported residual is the true one.
TEST(Gmres, SolvesNonsymmetricSystemWithRestarts) {
  const int n = 60;
  std::srand(7);
  const Eigen::MatrixXd A = Eigen::MatrixXd::Identity(n, n) + 0.3 / std::sqrt(n) * Eigen::MatrixXd::Random(n, n);
  const Eigen::VectorXd b = Eigen::VectorXd::Random(n);
  const Eigen::VectorXd exact = A.partialPivLu().solve(b);
  auto apply = [&](const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::VectorXd& y) { y = A * x; };
  const GmresResult r = gmres(apply, b, {1e-12, 10, 500});
  ASSERT_TRUE(r.converged) << r.relative_residual;
  EXPECT_GT(r.iterations, 10) << "the restart was exercised";
  EXPECT_LE(r.relative_residual, 1e-12);
  EXPECT_NEAR(r.relative_residual, (b - A * r.x).norm() / b.norm(), 1e-15);
  const double cond = 1 / (A.jacobiSvd().singularValues().minCoeff() / A.jacobiSvd().singularValues().maxCoeff());
  ASSERT_LT(cond, 10);
  EXPECT_LT((r.x - exact).norm() / exact.norm(), 1e-12 * cond);
}

// b = 0 gives x = 0 at once; a singular system with b outside the range cannot converge and says so
// (relative residual stays at the distance of b to the range, here 1/sqrt(2)).
TEST(Gmres, ZeroRightHandSideAndSingularSystem) {
  auto identity = [](const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::VectorXd& y) { y = x; };
  const GmresResult zero = gmres(identity, Eigen::VectorXd::Zero(5), {});
  EXPECT_TRUE(zero.converged);
  EXPECT_EQ(zero.iterations, 0);
  EXPECT_EQ(zero.x.norm(), 0.0);
  auto project = [](const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::VectorXd& y) {
    y = x;
    y[0] = 0;  // A = diag(0, 1, 1, ...)
  };
  Eigen::VectorXd b = Eigen::VectorXd::Zero(4);
  b[0] = 1, b[1] = 1;
  const GmresResult singular = gmres(project, b, {1e-10, 4, 20});
  EXPECT_FALSE(singular.converged);
  EXPECT_NEAR(singular.relative_residual, 1 / std::sqrt(2.0), 1e-12);
}

// The Arnoldi basis stays orthonormal where one Gram-Schmidt pass is not enough: A = I + 1e-6 R
// makes w = A v_j nearly a multiple of v_j, so the first pass removes all but ~1e-6 of w and its
// rounding (eps |w|) is ~1e-10 of what is left: without the DGKS second pass |V^T V - I| would be
// ~1e-10. Two passes leave O(n eps) ~ 1e-14 at n = 60; bound 1e-13. The basis is the workspace
// the caller passes (its first iterations + 1 columns: one cycle here), and a second call reusing
// it gives the same x bit for bit.
TEST(Gmres, BasisStaysOrthonormalWhenTheFirstPassCancels) {
  const int n = 60;
  std::srand(11);
  const Eigen::MatrixXd A = Eigen::MatrixXd::Identity(n, n) + 1e-6 * Eigen::MatrixXd::Random(n, n);
  const Eigen::VectorXd b = Eigen::VectorXd::Random(n);
  auto apply = [&](const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::VectorXd& y) { y = A * x; };
  Eigen::MatrixXd basis;
  const GmresResult r = gmres(apply, b, {1e-13, 20, 100}, &basis);
  ASSERT_GE(r.iterations, 2);
  ASSERT_LT(r.iterations, 20) << "one cycle";
  const Eigen::MatrixXd V = basis.leftCols(r.iterations + 1);
  EXPECT_LT((V.transpose() * V - Eigen::MatrixXd::Identity(V.cols(), V.cols())).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_LE(r.relative_residual, 1e-13);
  const GmresResult again = gmres(apply, b, {1e-13, 20, 100}, &basis);
  EXPECT_EQ(again.x, r.x);
}

// The levels: N, N/8, ... while >= coarse_N, then coarse_N itself when that is at most half the
// last, each a valid N for the grid.
TEST(ShootingLevels, GeometricAndValidForTheGrid) {
  const ImpactModel model(paper(1.0));
  EXPECT_EQ(shooting_levels(make_grid(model.tau(), model.period(), 1'000'000), 64, 8),
            (std::vector<int>{64, 244, 1953, 15625, 125000, 1000000}));
  EXPECT_EQ(shooting_levels(make_grid(model.tau(), model.period(), 2000), 64, 8), (std::vector<int>{64, 250, 2000}));
  EXPECT_EQ(shooting_levels(make_grid(model.tau(), model.period(), 511), 64, 8), (std::vector<int>{64, 511}));
  EXPECT_EQ(shooting_levels(make_grid(model.tau(), model.period(), 512), 64, 8), (std::vector<int>{64, 512}));
  EXPECT_EQ(shooting_levels(make_grid(model.tau(), model.period(), 128), 64, 8), (std::vector<int>{64, 128}));
  EXPECT_EQ(shooting_levels(make_grid(model.tau(), model.period(), 127), 64, 8), (std::vector<int>{127}));
  EXPECT_EQ(shooting_levels(make_grid(model.tau(), model.period(), 40), 64, 8), (std::vector<int>{40}));
  // tau = 3 T / 2: N must be a multiple of 3, so each level is (N / 8 rounded to a multiple of 3)
  // and the coarsest the first multiple of 3 from 64
  const double T = model.period();
  const std::vector<int> three = shooting_levels(make_grid(1.5 * T, T, 3000), 64, 8);
  EXPECT_EQ(three, (std::vector<int>{66, 375, 3000}));
  for (int N : three) EXPECT_NO_THROW(make_grid(1.5 * T, T, N)) << N;
  // tau = 2 T / 3: N multiple of 2
  const std::vector<int> two = shooting_levels(make_grid(2 * T / 3, T, 10000), 64, 8);
  EXPECT_EQ(two, (std::vector<int>{64, 156, 1250, 10000}));
  for (int N : two) EXPECT_NO_THROW(make_grid(2 * T / 3, T, N)) << N;
  EXPECT_THROW(shooting_levels(make_grid(T, T, 100), 0, 8), BadInput);
  EXPECT_THROW(shooting_levels(make_grid(T, T, 100), 64, 1), BadInput);
}

// The paper's stable orbit (tau = T, k = 0.2, aligned): nested shooting from N = 100 to 800 finds
// the orbit sparse-LU Newton and simulation find at N = 800. The three stop at |P(U) - U| <= 1e-13
// ... 1e-12 (1 + |U|) on different unknowns; the distance between fixed points is at most
// |(I - M)^{-1}| times that, with |mu_1| = 0.63 a few times 1e-12: bound 1e-10 relative.
// The finer level needs at most 4 Newton steps from the prolonged coarser orbit: measured
// |P(U) - U| 1.3e-3, 2.2e-4, 3.2e-6, 8.2e-10, 1.5e-13 (the first step is slowed by the contact,
// where the map is only piecewise smooth; then quadratic). At N = 1e5 from 12500: one step.
TEST(OrbitShooting, StableAlignedOrbitEqualsSparseNewtonAndSimulation) {
  ImpactSetup s(paper(0.2), 800);
  NestedShootingOptions o;
  o.coarse_N = 100;
  o.guess_periods = 100;
  OrbitLinearisation<2> at_orbit;
  const PeriodicOrbit shot = orbit_by_nested_shooting(s.map, s.model.initial_state(), o, &at_orbit);
  ASSERT_EQ(shot.levels.size(), 2u);
  EXPECT_EQ(shot.levels[0].N, 100);
  EXPECT_EQ(shot.levels[0].method, OrbitFoundBy::shooting);  // automatic: shooting, which converges here
  EXPECT_EQ(shot.method, OrbitFoundBy::shooting);
  EXPECT_LE(shot.newton_iterations, 4);
  EXPECT_GT(shot.linear_iterations, 0);
  EXPECT_LE(shot.residual, 1e-12 * (1 + shot.history.lpNorm<Eigen::Infinity>()));

  const PeriodicOrbit newton = sparse_newton(s, 100);
  EXPECT_LT(relative_distance(shot.history, newton.history), 1e-10);
  const PeriodicOrbit simulated =
      orbit_by_simulation(s.map, s.map.constant_history(s.model.initial_state()), {1e-13, 5000});
  EXPECT_LT(relative_distance(shot.history, simulated.history), 1e-10);

  // The linearisation handed back is the map's at the returned history: the same step maps as a
  // fresh evaluation there (bit for bit: the same arithmetic on the same input).
  ASSERT_EQ(at_orbit.maps.size(), static_cast<size_t>(s.grid.K));
  ASSERT_EQ(at_orbit.states.size(), static_cast<size_t>(s.grid.K + 1));
  std::vector<StepMap<2>> fresh;
  std::vector<Vec<2>> states;
  s.map.apply(shot.history, &fresh, &states);
  for (size_t l = 0; l < fresh.size(); l += 97) {
    EXPECT_EQ(at_orbit.maps[l].P, fresh[l].P) << l;
    EXPECT_EQ(at_orbit.maps[l].Q, fresh[l].Q) << l;
    EXPECT_EQ(at_orbit.states[l], states[l]) << l;
  }
}

// Fractional delay and a period-2 orbit (the PWSDDE-cont benchmark): shooting (every level,
// the coarsest too) and sparse-LU Newton agree to 1e-10 relative at N = 640.
TEST(OrbitShooting, FractionalDelayPeriodTwoEqualsSparseNewton) {
  ImpactSetup s(pwsdde_period_two(), 640, 2);
  ASSERT_GT(s.grid.theta, 0);
  NestedShootingOptions o;
  o.coarse_method = CoarseOrbitMethod::shooting;
  o.guess_periods = 10;
  const PeriodicOrbit shot = orbit_by_nested_shooting(s.map, s.model.initial_state(), o);
  ASSERT_EQ(shot.levels.size(), 2u);
  EXPECT_EQ(shot.levels[0].method, OrbitFoundBy::shooting);
  EXPECT_LE(shot.levels[1].newton_iterations, 3);
  const PeriodicOrbit newton = sparse_newton(s, 10);
  EXPECT_LT(relative_distance(shot.history, newton.history), 1e-10);
}

// The unstable orbit of tau = T, k = -0.1 (a multiplier near -1.9: simulation leaves it, see
// test_orbit_newton.cpp): nested shooting with no simulated periods (the guess is one map from
// the constant initial history, as for sparse Newton there) reaches it at N = 1024 and it equals
// sparse-LU Newton's; its leading multiplier is unstable.
TEST(OrbitShooting, UnstableOrbitSimulationCannotReach) {
  ImpactSetup s(paper(-0.1), 1024);
  NestedShootingOptions o;
  o.guess_periods = 0;
  OrbitLinearisation<2> at_orbit;
  const PeriodicOrbit shot = orbit_by_nested_shooting(s.map, s.model.initial_state(), o, &at_orbit);
  ASSERT_EQ(shot.levels.size(), 3u);               // 64, 128, 1024
  EXPECT_LE(shot.levels[2].newton_iterations, 4);  // measured 4: 1.2e-3, 1.1e-4, 6.8e-7, 5.1e-11, 6.7e-14
  const PeriodicOrbit newton = sparse_newton(s, 0);
  EXPECT_LT(relative_distance(shot.history, newton.history), 1e-10);
  FloquetOptions f;
  f.nev = 2;
  const FloquetResult mu = floquet_multipliers(Monodromy<2>(s.grid, std::move(at_orbit.maps)), f);
  EXPECT_GT(std::abs(mu.multipliers[0]), 1.5);
  EXPECT_THROW(
      orbit_by_simulation(s.map, shot.history + Eigen::VectorXd::Constant(shot.history.size(), 1e-6), {1e-12, 300}),
      NumericalFailure);
}

// auto's coarsest level: where shooting fails (here: one Newton step allowed, the simulated guess
// needs three at k = 1), sparse-LU Newton from the same guess finds the orbit, and it is the one
// sparse_newton finds (1e-10 relative, as above); where both fail the error names both.
TEST(OrbitShooting, AutomaticCoarseLevelFallsBackToSparseNewton) {
  ImpactSetup s(paper(1.0), 200);
  NestedShootingOptions o;
  o.coarse_N = 200;  // the coarsest level is the only one
  o.shooting.max_iterations = 1;
  const PeriodicOrbit orbit = orbit_by_nested_shooting(s.map, s.model.initial_state(), o);
  ASSERT_EQ(orbit.levels.size(), 1u);
  EXPECT_EQ(orbit.levels[0].method, OrbitFoundBy::newton);
  EXPECT_GE(orbit.newton_iterations, 2);
  EXPECT_LT(relative_distance(orbit.history, sparse_newton(s, 100).history), 1e-10);

  o.newton.max_iterations = 1;
  try {
    orbit_by_nested_shooting(s.map, s.model.initial_state(), o);
    FAIL() << "expected NumericalFailure";
  } catch (const NumericalFailure& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("shooting from the same guess failed first: orbit by shooting (N = 200): not converged"),
              std::string::npos)
        << what;
  }
  o.newton.max_iterations = 30;  // enough for the fallback, which orbit = shooting does not take
  o.coarse_method = CoarseOrbitMethod::shooting;
  EXPECT_THROW(orbit_by_nested_shooting(s.map, s.model.initial_state(), o), NumericalFailure);
}

// Failures: too few Newton steps names the level's N and |P(U) - U|; bad options are bad input.
TEST(OrbitShooting, FailurePathsAreReported) {
  ImpactSetup s(paper(0.2), 512);
  NestedShootingOptions o;
  o.shooting.max_iterations = 1;
  o.shooting.tolerance = 1e-15;  // one step from the prolonged N = 64 orbit cannot reach this
  try {
    orbit_by_nested_shooting(s.map, s.model.initial_state(), o);
    FAIL() << "expected NumericalFailure";
  } catch (const NumericalFailure& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("orbit by shooting (N = 512): not converged after 1 Newton iterations"), std::string::npos)
        << what;
    EXPECT_NE(what.find("|P(U) - U|_inf = "), std::string::npos) << what;
  }
  EXPECT_THROW(orbit_by_shooting(s.map, Eigen::VectorXd::Zero(7), {}), BadInput);
  OrbitByShootingOptions bad;
  bad.tolerance = 0;
  EXPECT_THROW(orbit_by_shooting(s.map, s.map.constant_history(s.model.initial_state()), bad), BadInput);
  Eigen::VectorXd nan_history = s.map.constant_history(s.model.initial_state());
  nan_history[1] = NAN;
  EXPECT_THROW(orbit_by_shooting(s.map, nan_history, {}), NumericalFailure);
}

// The CLI: `orbit = auto` (the default) at N = 600 goes through N = 75 and gives the multipliers
// of `orbit = simulate` (same orbit to ~1e-12, see above: 1e-9 leaves room for the multipliers'
// condition); a failing shooting level exits 3 naming the residual.
TEST(OrbitShootingCli, DefaultAutoMatchesSimulationAndReportsLevels) {
  const std::string scene = DELAYSPEC_SOURCE_DIR "/data/scenes/default.toml";
  CliResult automatic = run({"floquet", scene, "--json", "--set", "N=600", "--set", "nev=4"});
  ASSERT_EQ(automatic.status, 0) << automatic.err;
  const auto a = nlohmann::json::parse(automatic.out);
  EXPECT_EQ(a["orbit"]["method"], "shooting");
  ASSERT_EQ(a["orbit"]["levels"].size(), 2u);
  EXPECT_EQ(a["orbit"]["levels"][0]["N"], 75);
  EXPECT_EQ(a["orbit"]["levels"][0]["method"], "shooting");
  EXPECT_EQ(a["orbit"]["levels"][1]["N"], 600);
  EXPECT_TRUE(a.contains("orbit_seconds"));
  CliResult simulated =
      run({"floquet", scene, "--json", "--set", "N=600", "--set", "nev=4", "--set", "orbit=simulate"});
  ASSERT_EQ(simulated.status, 0) << simulated.err;
  const auto s = nlohmann::json::parse(simulated.out);
  for (int i = 0; i < 4; ++i)
    EXPECT_NEAR(a["multipliers"][i]["abs"].get<double>(), s["multipliers"][i]["abs"].get<double>(), 1e-9) << i;

  CliResult failing = run({"floquet", scene, "--set", "N=600", "--set", "orbit=shooting", "--set",
                           "orbit_max_iterations=1", "--set", "orbit_tolerance=1e-15"});
  EXPECT_EQ(failing.status, 3) << failing.err;
  EXPECT_NE(failing.err.find("|P(U) - U|_inf = "), std::string::npos) << failing.err;
  CliResult bad = run({"floquet", scene, "--set", "orbit_coarse_N=0"});
  EXPECT_EQ(bad.status, 2) << bad.err;
  EXPECT_NE(bad.err.find("orbit_coarse_N"), std::string::npos) << bad.err;
}
