// The branch of periodic orbits born at a Hopf point (hopf_branch.hpp).
//
// The circle oscillator (circle_oscillator.hpp) in mu: its equilibrium z = 0 has the roots
// mu +- i omega, a Hopf point at mu = 0 for every tau and k, in the discrete problem too (the
// trapezoid rule maps the imaginary axis onto the unit circle). Past it the discrete orbit is
// known in closed form (test_autonomous_orbit.cpp): a circle turned by the Cayley rotation,
// period T_K = (2 K / omega) tan(pi / K) for every mu, radius r^2 = mu (1 - k) / (1 - k c^2) (the
// fractional delay's chord c): the amplitude grows exactly like sqrt(mu - mu_H). In the rotating
// frame the multipliers other than the trivial one are exp(lambda T) with lambda = -2 mu + 2 k mu
// exp(-lambda tau).
//
// Mackey-Glass in tau (beta 0.2, gamma 0.1, n 10): the Hopf point of x* = 1 in closed form
// (test_equilibrium.cpp), the branch leaving it at the period 2 pi / omega with an amplitude
// growing like sqrt(tau - tau_H).
#include <cmath>
#include <complex>
#include <vector>

#include <gtest/gtest.h>

#include "circle_oscillator.hpp"
#include "delayspec/hopf_branch.hpp"
#include "delayspec/lambert_w.hpp"
#include "delayspec/model_mackey_glass.hpp"
#include "same_branch.hpp"

namespace delayspec {
namespace {

EquilibriumBifurcation hopf_at(double p, double omega, const Eigen::VectorXd& state) {
  EquilibriumBifurcation h;
  h.type = EquilibriumBifurcationType::hopf;
  h.parameter = p;
  h.omega = omega;
  h.period = 2 * M_PI / omega;
  h.state = state;
  return h;
}

TEST(HopfBranch, CircleOscillatorFollowsTheDiscreteClosedForm) {
  const Circle base;
  auto circle_at = [&base](double mu) {
    Circle c = base;
    c.mu = mu;
    return c;
  };
  ContinuationOptions o;
  o.from = -0.5;
  o.to = 1;
  o.N = 40;
  o.floquet.nev = 3;
  const ContinuationResult r = continue_from_hopf<Circle>(circle_at, hopf_at(0, base.omega, Eigen::Vector2d::Zero()), o);
  ASSERT_EQ(r.end, BranchEnd::to) << r.failure;
  ASSERT_GE(r.points.size(), 5u);
  EXPECT_EQ(r.bifurcations.size(), 0u);
  const int K = static_cast<int>(std::round(o.N * (2 * M_PI / base.omega) / base.delay));
  const double T_K = 2 * K * std::tan(M_PI / K) / base.omega;
  EXPECT_DOUBLE_EQ(r.points[0].period, 2 * M_PI / base.omega);  // the start: the Hopf point itself
  for (size_t i = 1; i < r.points.size(); ++i) {
    const ContinuationPoint& pt = r.points[i];
    const double mu = pt.parameter;
    ASSERT_GT(mu, 0) << "the orbits are born towards mu > 0";
    // The period: Newton's residual 1e-12 (1 + |x|) over dF/dT ~ r / K per step (F_T is the
    // rotation's velocity, proportional to the radius): 1e-12 K / r
    const double alpha = 2 * std::atan(base.omega * pt.period / (2 * K));
    const HistoryGrid g = make_grid_with_steps({base.delay / pt.period}, 1.0, K);
    const double c2 = 1 - 2 * g.theta * (1 - g.theta) * (1 - std::cos(alpha));
    const double r2 = mu * (1 - base.k) / (1 - base.k * c2);
    EXPECT_NEAR(pt.period, T_K, 1e-12 * K / std::sqrt(r2)) << "mu = " << mu;
    // The radius from the nodes' extremes: max_l r cos(phi_0 + 2 pi l / K) lies in [r cos(pi / K),
    // r], r known to Newton's residual 1e-12 (1 + |x|) over the radial contraction per step,
    // 2 mu (1 - k) T / K (the slowest decay of rho' = -2 mu rho + 2 k mu rho(t - tau) at leading order)
    const double r = std::sqrt(r2), r_tolerance = 1e-12 * 2 * K / (2 * mu * (1 - base.k) * pt.period);
    for (int c = 0; c < 2; ++c) {
      EXPECT_LE(pt.measures.max[c], r + r_tolerance) << "mu = " << mu;
      EXPECT_GE(pt.measures.max[c], r * std::cos(M_PI / K) - r_tolerance) << "mu = " << mu;
    }
    // The trivial multiplier apart, 1 to the eigensolver's accuracy (the rotation symmetry)
    EXPECT_LT(std::abs(pt.trivial_multiplier - 1.0), 1e-9) << "mu = " << mu;
    // The others against the rotating frame's roots, to the discretisation's O(h^2): 2e-3 at K
    // = 100 (test_autonomous_orbit.cpp), scaled by (100 / K)^2 and by mu (the roots scale with mu)
    const std::vector<std::complex<double>> roots = linear_dde_roots(-2 * mu, 2 * base.k * mu, base.delay, 8);
    ASSERT_EQ(pt.multipliers.size(), 3u);
    for (const auto& m : pt.multipliers) {
      double best = INFINITY;
      for (auto l : roots) best = std::min(best, std::abs(m - std::exp(l * pt.period)));
      EXPECT_LT(best, 2e-3 * std::max(mu, 0.1) * (100.0 / K) * (100.0 / K)) << m << " at mu = " << mu;
    }
  }
}

// Mackey-Glass (beta 0.2, gamma 0.1, n 10) as a family in tau, and the Hopf point of x* = 1 in
// closed form (test_equilibrium.cpp): x' = -gamma x + b x(t - tau), b = beta (2 - n) / 4 < 0; at
// lambda = i omega, cos(omega tau) = gamma / b and sin(omega tau) = -omega / b.
struct MackeyGlassInTau {
  MackeyGlassParameters base;
  MackeyGlassInTau() { base.tau = base.period = 5; }
  MackeyGlassModel operator()(double tau) const {
    MackeyGlassParameters p = base;
    p.tau = tau;
    return MackeyGlassModel(p);
  }
  double b() const { return base.beta * (2 - base.n) / 4; }
  double omega() const { return std::sqrt(b() * b() - base.gamma * base.gamma); }
  double tau_H() const { return std::acos(base.gamma / b()) / omega(); }
};

TEST(HopfBranch, MackeyGlassStartsAtThePredictedPeriodAndGrowsLikeASquareRoot) {
  const MackeyGlassInTau mg_at;
  const double omega = mg_at.omega(), tau_H = mg_at.tau_H();
  // Near the Hopf point a^2 = c1 (tau - tau_N) + c2 (tau - tau_N)^2 + ...: the discrete Hopf point
  // tau_N is where the parabola through the first points meets 0 (least squares), and it tends
  // to tau_H as h^2. Not at a clean observed order: K = round(N T_0 / tau_max) puts the delay at a
  // fractional position theta that changes with N, and the h^2 term's constant depends on theta
  // (measured: (tau_N - tau_H) (N / 100)^2 = 2.3e-4, 1.7e-4, 2.1e-4 at N = 100, 200, 400). So the
  // bound: within 1.5 times the first level's, scaled by h^2.
  std::vector<double> offsets;
  for (int N : {100, 200, 400}) {
    ContinuationOptions o;
    o.from = 4;
    o.to = 4.75;
    o.step = o.step_max = 0.004;
    o.N = N;
    const ContinuationResult r =
        continue_from_hopf<MackeyGlassModel>(mg_at, hopf_at(tau_H, omega, Eigen::VectorXd::Ones(1)), o);
    ASSERT_EQ(r.end, BranchEnd::to) << r.failure;
    ASSERT_GE(r.points.size(), 7u);
    EXPECT_EQ(r.points[0].period, 2 * M_PI / omega);
    EXPECT_EQ(r.points[0].parameter, tau_H);
    // The first point past the Hopf point: amplitude a ~ 0.004, its period 2 pi / omega + O(a^2) +
    // O(h^2) (measured offsets: 2.6e-3 relative at N = 100)
    EXPECT_NEAR(r.points[1].period, 2 * M_PI / omega, 1e-3 * 2 * M_PI / omega);
    constexpr int kPoints = 6;
    Eigen::MatrixXd V(kPoints, 3);
    Eigen::VectorXd a2(kPoints);
    for (int i = 0; i < kPoints; ++i) {
      const ContinuationPoint& pt = r.points[static_cast<size_t>(i + 1)];
      EXPECT_GT(pt.parameter, tau_H) << "supercritical: the orbits exist for tau > tau_H";
      const double s = pt.parameter - tau_H, a = (pt.measures.max[0] - pt.measures.min[0]) / 2;
      V.row(i) << 1, s, s * s;
      a2[i] = a * a;
    }
    const Eigen::Vector3d q = V.colPivHouseholderQr().solve(a2);  // a^2 = q0 + q1 s + q2 s^2
    const double s_N = -q[0] / q[1];                               // its root near 0 (q2 s^2 negligible there)
    offsets.push_back(s_N);
    // a = sqrt(q(tau)): the square-root law, to the neglected cubic term
    for (int i = 0; i < kPoints; ++i)
      EXPECT_NEAR(std::sqrt(a2[i]), std::sqrt((V.row(i) * q)(0)), 1e-3 * std::sqrt(a2[i])) << "N = " << N;
  }
  EXPECT_GT(offsets[0], 0);
  EXPECT_LT(offsets[0], 1e-3) << "the discrete Hopf point at N = 100 is O(h^2) from the exact one";
  for (size_t i = 1; i < offsets.size(); ++i) {
    const double scale = std::pow(2.0, -2.0 * static_cast<double>(i));  // (100 / N)^2
    EXPECT_LT(std::abs(offsets[i]), 1.5 * offsets[0] * scale) << "N = " << (100 << i) << ": " << offsets[i];
    EXPECT_GT(std::abs(offsets[i]), 0.5 * offsets[0] * scale) << "N = " << (100 << i) << ": " << offsets[i];
  }
}

// Further along the Mackey-Glass branch: a period doubling (the first of the cascade to chaos),
// detected among the multipliers other than the trivial one and located where one is -1.
// Checked against orbits found apart (find_autonomous_orbit at N = 400, its own K): the leading
// multiplier there is above -1 just before the located tau and below just after (the margin,
// 0.05 in tau, covers the two discretisations' O(h^2) difference).
TEST(HopfBranch, MackeyGlassBranchHasAPeriodDoublingWhereAMultiplierIsMinusOne) {
  const MackeyGlassInTau mg_at;
  ContinuationOptions o;
  o.from = 4;
  o.to = 14;
  o.N = 100;
  const ContinuationResult r = continue_from_hopf<MackeyGlassModel>(
      mg_at, hopf_at(mg_at.tau_H(), mg_at.omega(), Eigen::VectorXd::Ones(1)), o);
  ASSERT_EQ(r.end, BranchEnd::to) << r.failure;
  ASSERT_EQ(r.bifurcations.size(), 1u);
  const Bifurcation& pd = r.bifurcations[0];
  EXPECT_EQ(pd.type, BifurcationType::period_doubling);
  EXPECT_LT(pd.bracket, 1e-8);
  EXPECT_NEAR(pd.period, pd.orbit[pd.orbit.size() - 1], 0);
  for (double side : {-1.0, 1.0}) {
    AutonomousOrbitOptions ao;
    ao.period_guess = pd.period;
    ao.N = 400;
    ao.guess_periods = 60;
    const MackeyGlassModel model = mg_at(pd.parameter + 0.05 * side);
    const AutonomousOrbit orbit = find_autonomous_orbit(model, ao);
    FloquetOptions fo;
    fo.nev = 3;
    const FloquetResult f = floquet_multipliers(autonomous_orbit_map(model, orbit).monodromy(orbit.history), fo);
    double most_negative = 0;
    for (const auto& mu : f.multipliers)
      if (std::abs(mu.imag()) < 1e-10 && mu.real() < most_negative) most_negative = mu.real();
    if (side < 0) EXPECT_GT(most_negative, -1) << "before the period doubling";
    else EXPECT_LT(most_negative, -1) << "after the period doubling";
  }
}

// Issue 36, item 3: the corrector's two solvers on an orbit of unknown period, whose bordered
// system has two borders (F_T and the phase row besides F_p): the same branch, the same period
// doubling, and no matrix factored by GMRES' corrector.
TEST(HopfBranch, KrylovAndLuCorrectorsGiveTheSameMackeyGlassBranch) {
  const MackeyGlassInTau mg_at;
  ContinuationOptions o;
  o.from = 4;
  o.to = 14;
  o.N = 100;
  const EquilibriumBifurcation hopf = hopf_at(mg_at.tau_H(), mg_at.omega(), Eigen::VectorXd::Ones(1));
  o.solver = ContinuationSolver::lu;
  const ContinuationResult lu = continue_from_hopf<MackeyGlassModel>(mg_at, hopf, o);
  o.solver = ContinuationSolver::krylov;
  const ContinuationResult krylov = continue_from_hopf<MackeyGlassModel>(mg_at, hopf, o);
  ASSERT_EQ(lu.end, BranchEnd::to) << lu.failure;
  ASSERT_EQ(lu.bifurcations.size(), 1u);
  testing::expect_same_branch(lu, krylov);
}

}  // namespace
}  // namespace delayspec
