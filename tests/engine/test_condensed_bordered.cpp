// Continuation's matrix-free corrector (detail/condensed_bordered.hpp, ContinuationSolver).
//
// The condensed solve is checked against what it replaces: the assembled bordered matrix
// [F_x F_p; row_x row_p] (PeriodicOrbitProblem's sparse Jacobian, itself checked against finite
// differences in test_orbit_newton.cpp) times the solution gives back the right-hand side, and
// UMFPACK's factorisation of that matrix gives the same solution. At iterates that are not orbits
// (the identity holds at any x), with events, a fractional delay, several delays, and at a fold
// (F_x singular, the bordered matrix not). Then whole branches: the Krylov and the sparse-LU
// corrector give the same points, multipliers and bifurcations, and the automatic choice falls
// back to the LU where GMRES fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "delayspec/continuation.hpp"
#include "delayspec/detail/condensed_bordered.hpp"
#include "delayspec/detail/sparse_lu.hpp"
#include "delayspec/model_impact.hpp"
#include "delayspec/orbit_newton.hpp"
#include "impact_gap_branch.hpp"
#include "saddle_node_model.hpp"
#include "same_branch.hpp"

namespace delayspec {
namespace {

using std::numbers::pi;
using testing::expect_same_branch;
using testing::SaddleNodeDelayModel;

// d = 2, two delays, nonlinear and forced: x' = y, y' = -c y - x^3 + k1 x(t - tau1) + k2 sin(y(t -
// tau2)) + cos(2 pi t / T). Both delays fractional on the grids below.
struct CubicTwoDelayOscillator {
  static constexpr int d = 2;
  static constexpr int delay_count = 2;
  static constexpr bool has_switching = false, affine_in_state = false, is_linear = false;
  double c = 0.2, k1 = 0.3, k2 = -0.4, tau1 = 0.7, tau2 = std::sqrt(1.7), T = 1.3;
  std::array<double, 2> delays() const { return {tau1, tau2}; }
  double tau() const { return std::max(tau1, tau2); }
  double period() const { return T; }
  Vec<2> f(int, double t, const Vec<2>& y, const Vec<4>& z) const {
    return Vec<2>(y[1], -c * y[1] - y[0] * y[0] * y[0] + k1 * z[0] + k2 * std::sin(z[3]) + std::cos(2 * pi * t / T));
  }
  Mat<2> A(int, double, const Vec<2>& y, const Vec<4>&) const {
    return (Mat<2>() << 0, 1, -3 * y[0] * y[0], -c).finished();
  }
  RectMat<2, 4> B(int, double, const Vec<2>&, const Vec<4>& z) const {
    RectMat<2, 4> b = RectMat<2, 4>::Zero();
    b(1, 0) = k1;
    b(1, 3) = k2 * std::cos(z[3]);
    return b;
  }
  Vec<2> initial_state() const { return Vec<2>(0.5, 0); }
};
static_assert(DelayModel<CubicTwoDelayOscillator>);

template <class Model>
StroboscopicMap<Model> forced_map(const Model& model, int N, int periods_per_map = 1) {
  return StroboscopicMap<Model>(TrapezoidStepper<Model>(model),
                                make_grid(delays_of(model), model.period(), N, periods_per_map));
}

Eigen::VectorXd random_vector(long n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::VectorXd v(n);
  for (long i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

// A sequence of d = 2 states that is not an orbit: x = A sin(w t) + a second harmonic, v its
// derivative, over K steps of h.
Eigen::VectorXd test_sequence(long K, double h, double amplitude, double w) {
  Eigen::VectorXd x(2 * K);
  for (long l = 0; l < K; ++l) {
    const double t = static_cast<double>(l) * h;
    x[2 * l] = amplitude * std::sin(w * t) + 0.1 * std::cos(2 * w * t);
    x[2 * l + 1] = amplitude * w * std::cos(w * t) - 0.2 * w * std::sin(2 * w * t);
  }
  return x;
}

struct Border {
  Eigen::VectorXd F_p, row_x;
  double row_p = 0;
};

// Solves the bordered system at x both ways and checks them (file comment). The condensed solve
// is asked for a relative residual of 1e-13 (GMRES' floor); the residual of the assembled system
// is the condensed one carried through one step (|P|, |Q|, |R| = O(1) at these h) plus the
// sweep's rounding, about K eps |z| (K <= 700 here): 1e-11 (|rhs| + |z|) bounds both with a
// factor 10-100 to spare (measured 4e-16 ... 3e-15). The two solutions then differ by at most the
// matrix's condition times that relative residual, each solution's share: 2e-11 / rcond with
// UMFPACK's rcond (a crude estimate from U's diagonal, 0.008 ... 0.49 here; the differences
// measured 8e-16 ... 2e-14, far inside). A wrong solve (a sign, a block one step off) is off by O(1).
template <class Map>
void expect_solves_like_lu(const Map& map, const Eigen::VectorXd& x, const Border* given, unsigned seed) {
  constexpr int D = Map::D;
  PeriodicOrbitProblem<Map> problem(map);
  Eigen::SparseMatrix<double> F_x;
  std::vector<StepMap<D, Map::DW>> maps;
  Eigen::VectorXd F = problem.residual(x, &F_x, &maps);
  const long n = x.size();
  std::mt19937 rng(seed);
  Border border = given ? *given : Border{random_vector(n, rng), random_vector(n, rng) / n, 0.7};
  const Eigen::VectorXd rhs_x = random_vector(n, rng);
  const double rhs_p = 0.3;
  continuation_detail::Borders borders{border.F_p, border.row_x.transpose(),
                                       Eigen::MatrixXd::Constant(1, 1, border.row_p)};
  continuation_detail::CondensedBordered<D, Map::DW> condensed(F, map.grid(), std::move(maps), std::move(borders), 0.0,
                                                               {});
  std::string why;
  const std::optional<Eigen::VectorXd> z = condensed.solve(rhs_x, rhs_p, 1e-13, why);
  ASSERT_TRUE(z) << why;
  EXPECT_EQ(condensed.factorisations, 0);
  EXPECT_GT(condensed.products, 0);
  EXPECT_EQ(condensed.G, F);  // the iterate's residual, as given

  const Eigen::SparseMatrix<double> A = bordered_matrix(F_x, border.F_p, border.row_x, border.row_p);
  Eigen::VectorXd rhs(n + 1);
  rhs << rhs_x, rhs_p;
  const double residual = (A * *z - rhs).lpNorm<Eigen::Infinity>();
  EXPECT_LE(residual, 1e-11 * (rhs.lpNorm<Eigen::Infinity>() + z->lpNorm<Eigen::Infinity>()));
  const SparseLU lu(A);
  const Eigen::VectorXd z_lu = lu.solve(rhs);
  EXPECT_LE((*z - z_lu).lpNorm<Eigen::Infinity>(), 2e-11 / lu.reciprocal_condition() * z_lu.lpNorm<Eigen::Infinity>())
      << "residual " << residual << ", |z| " << z_lu.lpNorm<Eigen::Infinity>();
}

TEST(CondensedBordered, SolvesAsTheLuWithEventsAndAFractionalDelay) {
  // The PWSDDE-cont system (data/scenes/continue_pwsdde_k.toml): tau = 3.8 against T = 2 pi / 0.8,
  // two forcing periods per map; the sequence reaches x = 1.5 > e = 1.26, so steps have impacts.
  ImpactParameters p;
  p.zeta = 0.01, p.e = 1.26, p.a = 0.9, p.beta = 29, p.omega = 0.8, p.k = 0.2, p.tau = 3.8;
  const ImpactModel model(p);
  for (int N : {40, 101}) {
    const auto map = forced_map(model, N, 2);
    ASSERT_FALSE(map.grid().aligned());
    const Eigen::VectorXd x = test_sequence(map.grid().K, map.grid().h, 1.5, p.omega);
    SCOPED_TRACE("N = " + std::to_string(N));
    expect_solves_like_lu(map, x, nullptr, 7u + static_cast<unsigned>(N));
  }
}

TEST(CondensedBordered, SolvesAsTheLuWithTwoDelays) {
  const CubicTwoDelayOscillator model;
  const auto map = forced_map(model, 60);
  const Eigen::VectorXd x = test_sequence(map.grid().K, map.grid().h, 0.8, 2 * pi / model.T);
  expect_solves_like_lu(map, x, nullptr, 3u);
}

TEST(CondensedBordered, SolvesAsTheLuAtAFoldWhereFxIsSingular) {
  // At p = 0, x = 0 the saddle-node's F_x has the constant sequence as null vector (f_x = -2 x -
  // c + c e^{...} = 0 on constants), so M - I is singular; bordered with F_p (f_p = 1: -h per
  // step, with the trapezoid rule) and the mean as row, the matrix is regular.
  const SaddleNodeDelayModel model{0, 0.5};
  const int N = 50;
  const auto map = forced_map(model, N);
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(N);
  Eigen::SparseMatrix<double> F_x;
  PeriodicOrbitProblem<StroboscopicMap<SaddleNodeDelayModel>>(map).residual(x, &F_x);
  EXPECT_LE((F_x * Eigen::VectorXd::Ones(N)).lpNorm<Eigen::Infinity>(), 1e-15);  // singular indeed
  const Border border{Eigen::VectorXd::Constant(N, -map.grid().h), Eigen::VectorXd::Constant(N, 1.0 / N), 0};
  expect_solves_like_lu(map, x, &border, 5u);
}

template <class Model, class ModelAt>
std::array<ContinuationResult, 2> both_solvers(const ModelAt& model_at, const Eigen::VectorXd& guess,
                                               ContinuationOptions o) {
  o.solver = ContinuationSolver::lu;
  ContinuationResult lu = continue_orbit<Model>(model_at, guess, o);
  o.solver = ContinuationSolver::krylov;
  return {std::move(lu), continue_orbit<Model>(model_at, guess, o)};
}

TEST(ContinuationSolvers, KrylovAndLuGiveTheSameImpactBranchThroughGrazingAndNeimarkSacker) {
  // The impact orbit at tau = T continued in the gap e (impact_gap_branch.hpp): stable and free,
  // grazing, in contact, unstable past a Neimark-Sacker point.
  const ImpactParameters base;
  const int N = 100;
  const Eigen::VectorXd guess = testing::free_orbit_sequence(base, N);
  ContinuationOptions o;
  o.from = 1.3;
  o.to = 1.2;
  o.N = N;
  o.tolerance = 1e-12;
  const testing::ImpactInGap model_at{base, 0.5};
  const auto [lu, krylov] = both_solvers<ImpactModel>(model_at, guess, o);
  ASSERT_EQ(lu.end, BranchEnd::to) << lu.failure;
  std::vector<BifurcationType> types;
  for (const auto& b : lu.bifurcations) types.push_back(b.type);
  EXPECT_NE(std::find(types.begin(), types.end(), BifurcationType::grazing), types.end());
  EXPECT_NE(std::find(types.begin(), types.end(), BifurcationType::neimark_sacker), types.end());
  EXPECT_GT(lu.points.back().unstable, 0);  // the branch ends on unstable orbits
  expect_same_branch(lu, krylov);
}

// The saddle-node with tau = 1 against a period 0.77: fractional on the grid.
struct FractionalSaddleNode : SaddleNodeDelayModel {
  double period() const { return 0.77; }
};
const auto fractional_saddle_node = [](double p) {
  FractionalSaddleNode m;
  m.p = p;
  return m;
};

TEST(ContinuationSolvers, KrylovAndLuGiveTheSameBranchThroughAFoldWithAFractionalDelay) {
  // The branch turns at p = 0 and comes back on the unstable equilibria.
  ContinuationOptions o;
  o.from = 1;
  o.to = -1;
  o.N = 40;
  o.tolerance = 1e-12;
  const long K = make_grid(1.0, 0.77, 40).K;
  const auto [lu, krylov] =
      both_solvers<FractionalSaddleNode>(fractional_saddle_node, Eigen::VectorXd::Constant(K, 1.0), o);
  ASSERT_EQ(lu.end, BranchEnd::from) << lu.failure;
  ASSERT_EQ(lu.bifurcations.size(), 1u);
  EXPECT_NEAR(lu.bifurcations[0].parameter, 0, 1e-12);  // exact for every N (saddle_node_model.hpp)
  EXPECT_EQ(lu.points.back().unstable, 1);
  expect_same_branch(lu, krylov);
}

TEST(ContinuationSolvers, AutomaticFallsBackToTheLuWhereGmresFails) {
  // One GMRES product per solve cannot reach the forcing term: every solve fails. auto then
  // takes the sparse LU for it (the branch is the LU's), krylov alone cannot start and says why.
  ContinuationOptions o;
  o.from = 1;
  o.to = 0.5;
  o.N = 60;
  o.gmres_max_iterations = 1;
  const long K = make_grid(1.0, 0.77, 60).K;
  const Eigen::VectorXd guess = Eigen::VectorXd::Constant(K, 1.0);
  o.solver = ContinuationSolver::lu;
  const ContinuationResult lu = continue_orbit<FractionalSaddleNode>(fractional_saddle_node, guess, o);
  o.solver = ContinuationSolver::automatic;
  const ContinuationResult automatic = continue_orbit<FractionalSaddleNode>(fractional_saddle_node, guess, o);
  ASSERT_EQ(lu.end, BranchEnd::to) << lu.failure;
  EXPECT_EQ(automatic.factorisations, lu.factorisations);
  EXPECT_GT(automatic.gmres_products, 0);  // tried first, every time
  ASSERT_EQ(automatic.points.size(), lu.points.size());
  for (size_t i = 0; i < lu.points.size(); ++i) EXPECT_EQ(automatic.points[i].parameter, lu.points[i].parameter);
  o.solver = ContinuationSolver::krylov;
  try {
    continue_orbit<FractionalSaddleNode>(fractional_saddle_node, guess, o);
    ADD_FAILURE() << "no failure";
  } catch (const NumericalFailure& e) {
    EXPECT_NE(std::string(e.what()).find("GMRES on the condensed bordered system did not converge"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace delayspec
