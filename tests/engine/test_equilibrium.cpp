// Equilibria and their characteristic roots (equilibrium.hpp), against references the engine does
// not produce:
//  * x' = a x + b x(t - tau): the roots are Lambert-W values, lambda = a + W_k(b tau e^{-a tau}) / tau
//    (lambert_w.hpp), for a leading real root and a leading complex pair;
//  * Mackey-Glass at its equilibrium x* = 1 (beta / gamma = 2): the linearisation is
//    x' = -gamma x + beta (2 - n) / 4 x(t - tau), again Lambert W;
//  * a d = 2 system with two delays: roots by Newton on its characteristic function from a grid
//    of starts (tests/support/characteristic_roots.hpp), mapped back from exp(lambda T).
// After refinement on the exact characteristic function the roots carry no discretisation error:
// 1e-12 (Newton's stopping test is 1e-12 relative; the Lambert-W values are good to ~1e-15).
#include <algorithm>
#include <cmath>
#include <complex>
#include <iostream>
#include <tuple>

#include <gtest/gtest.h>

#include "characteristic_roots.hpp"
#include "delayspec/equilibrium.hpp"
#include "delayspec/equilibrium_branch.hpp"
#include "delayspec/lambert_w.hpp"
#include "delayspec/model_linear.hpp"
#include "delayspec/model_mackey_glass.hpp"

namespace delayspec {
namespace {

using cd = std::complex<double>;

void expect_roots(const EquilibriumResult& r, const std::vector<cd>& exact, size_t count, double tol) {
  ASSERT_GE(r.roots.size(), count);
  for (size_t i = 0; i < count; ++i) {
    double best = INFINITY;
    for (cd e : exact) best = std::min(best, std::abs(r.roots[i].value - e));
    EXPECT_LT(best, tol) << "root " << i << " = " << r.roots[i].value;
  }
  // rightmost first, and every exact root to the right of the last reported one is reported
  for (size_t i = 1; i < r.roots.size(); ++i) EXPECT_GE(r.roots[i - 1].value.real(), r.roots[i].value.real());
  for (cd e : exact)
    if (e.real() > r.roots[count - 1].value.real() + 1e-9) {
      double best = INFINITY;
      for (const auto& root : r.roots) best = std::min(best, std::abs(root.value - e));
      EXPECT_LT(best, tol) << "missed the exact root " << e;
    }
}

TEST(Equilibrium, ScalarLinearRootsAreTheLambertWRoots) {
  // a = -1, b = 0.5: a real leading root; a = -1, b = -3: an unstable complex leading pair
  for (const auto& [a, b] : {std::pair{-1.0, 0.5}, std::pair{-1.0, -3.0}}) {
    SCOPED_TRACE("a = " + std::to_string(a) + ", b = " + std::to_string(b));
    const LinearModel model({.a = a, .b = b, .tau = 1, .period = 1});
    EquilibriumOptions o;
    o.nroots = 6;
    const EquilibriumResult r = find_equilibrium(model, Vec<1>(0.3), o);
    EXPECT_NEAR(r.state[0], 0, 1e-15);
    const std::vector<cd> exact = linear_dde_roots(a, b, 1, 12);
    expect_roots(r, exact, 6, 1e-12);
    std::cout << "a = " << a << ", b = " << b << ": rightmost root " << r.roots[0].value << ", moved "
              << std::abs(r.roots[0].value - r.roots[0].discretised) << " by the refinement\n";
    // the discretisation's error at N = 100 is what refinement removed: second order, ~1e-4
    EXPECT_GT(std::abs(r.roots[0].value - r.roots[0].discretised), 1e-9);
    EXPECT_LT(std::abs(r.roots[0].value - r.roots[0].discretised), 1e-2);
    EXPECT_EQ(r.unstable, exact.front().real() > 0 ? (exact.front().imag() != 0 ? 2 : 1) : 0);
  }
}

TEST(Equilibrium, MackeyGlassEquilibriumAndItsRoots) {
  MackeyGlassParameters p;  // beta 0.2, gamma 0.1, n 10
  p.tau = 2;
  p.period = 2;
  const MackeyGlassModel model(p);
  const EquilibriumResult r = find_equilibrium(model, Vec<1>(1.05));
  EXPECT_NEAR(r.state[0], 1, 1e-14);
  EXPECT_LT(r.residual, 1e-15);
  const double b = p.beta * (2 - p.n) / 4;  // d/dw beta w / (1 + w^n) at w = 1
  expect_roots(r, linear_dde_roots(-p.gamma, b, p.tau, 12), 6, 1e-12);
}

// x' = y, y' = -c y - x + k1 x(t - tau1) + k2 y(t - tau2)
struct TwoDelayOscillator {
  static constexpr int d = 2;
  static constexpr int delay_count = 2;
  static constexpr bool has_switching = false, affine_in_state = true, is_linear = true, autonomous = true;
  double c = 0.1, k1 = 0.3, k2 = -0.6, tau1 = 0.7, tau2 = std::sqrt(1.7);
  std::array<double, 2> delays() const { return {tau1, tau2}; }
  double tau() const { return tau2; }
  double period() const { return 1; }
  Vec<2> f(int, double, const Vec<2>& y, const Vec<4>& z) const {
    return Vec<2>(y[1], -c * y[1] - y[0] + k1 * z[0] + k2 * z[3]);
  }
  Mat<2> A(int, double, const Vec<2>&, const Vec<4>&) const { return (Mat<2>() << 0, 1, -1, -c).finished(); }
  RectMat<2, 4> B(int, double, const Vec<2>&, const Vec<4>&) const {
    RectMat<2, 4> b = RectMat<2, 4>::Zero();
    b(1, 0) = k1;
    b(1, 3) = k2;
    return b;
  }
  Vec<2> initial_state() const { return Vec<2>(0, 0); }
};

TEST(Equilibrium, TwoDelaySystemRootsAgainstItsCharacteristicFunction) {
  const TwoDelayOscillator m;
  const EquilibriumResult r = find_equilibrium(m, Vec<2>(0.5, -0.2));
  EXPECT_LT(r.state.cwiseAbs().maxCoeff(), 1e-14);
  // lambda^2 + c lambda + 1 - k1 e1 - k2 lambda e2, found independently (T = 1: lambda = log mu)
  const test::Characteristic ch{
      [m](cd l) { return l * (l + m.c - m.k2 * std::exp(-l * m.tau2)) + 1.0 - m.k1 * std::exp(-l * m.tau1); },
      [m](cd l) {
        const cd e1 = std::exp(-l * m.tau1), e2 = std::exp(-l * m.tau2);
        return 2.0 * l + m.c - m.k2 * e2 + m.k2 * m.tau2 * l * e2 + m.k1 * m.tau1 * e1;
      }};
  std::vector<cd> exact;
  for (cd mu : test::exact_multipliers(ch, 1, -12, 60)) exact.push_back(std::log(mu));  // Im in (-pi, pi]
  // compare modulo 2 pi i: the multipliers' logarithm loses the branch; the reported roots must
  // be roots of c themselves, which Newton's last step checks
  for (size_t i = 0; i < 6; ++i) {
    double best = INFINITY;
    for (cd e : exact)
      for (int k = -20; k <= 20; ++k) best = std::min(best, std::abs(r.roots[i].value - (e + cd(0, 2 * M_PI * k))));
    EXPECT_LT(best, 1e-10) << r.roots[i].value;
    EXPECT_LT(std::abs(ch.value(r.roots[i].value)), 1e-10 * (1 + std::norm(r.roots[i].value)));
  }
}

// Issue 61 item 2: Mackey-Glass at x* = 1, tau = 17: one unstable pair, then stable pairs (its
// roots are Lambert-W values). With a loose equilibrium_tolerance
// (1e-3 .. 2e-4) the same six roots come back, conjugates together and within their bounds of the
// exact ones; before, roots within 1e3 tolerance (1 + |lambda|) of each other were merged: 1 root
// instead of 6 at 1e-3 (its conjugate lost, "1 root with Re > 0" for 2), a non-rightmost set at
// 2e-4 .. 5e-4. A cut through a pair keeps the pair (nroots = 1 gives both roots, with a note).
TEST(Equilibrium, LooseTolerancesKeepEveryRootAndConjugatesTogether) {
  MackeyGlassParameters p;
  p.tau = p.period = 17;
  const MackeyGlassModel model(p);
  const double b = p.beta * (2 - p.n) / 4;
  const std::vector<cd> exact = linear_dde_roots(-p.gamma, b, p.tau, 12);
  for (double tolerance : {1e-3, 5e-4, 2e-4, 1e-12}) {
    SCOPED_TRACE("tolerance " + std::to_string(tolerance));
    EquilibriumOptions o;
    o.tolerance = tolerance;
    const EquilibriumResult r = find_equilibrium(model, Vec<1>(1.1), o);
    ASSERT_EQ(r.roots.size(), 6u);
    EXPECT_TRUE(r.note.empty()) << r.note;
    EXPECT_EQ(r.unstable, 2);
    for (size_t i = 0; i < 6; ++i) {
      double nearest = INFINITY;
      for (cd e : exact) nearest = std::min(nearest, std::abs(r.roots[i].value - e));
      // within the root's bound, and the Lambert-W value's own rounding, 1e-14
      EXPECT_LE(nearest, r.roots[i].error_bound + 1e-14) << r.roots[i].value;
      EXPECT_NEAR(r.roots[i].value.real(), r.roots[i ^ 1].value.real(), 1e-15) << i;  // pairs side by side
      EXPECT_EQ(r.roots[i].value.imag(), -r.roots[i ^ 1].value.imag()) << i;
    }
  }
  EquilibriumOptions one;
  one.nroots = 1;
  const EquilibriumResult r = find_equilibrium(model, Vec<1>(1.1), one);
  ASSERT_EQ(r.roots.size(), 2u);
  EXPECT_EQ(r.roots[1].value, std::conj(r.roots[0].value));
  EXPECT_NE(r.note.find("not cut in two"), std::string::npos) << r.note;
  EXPECT_EQ(r.unstable, 2);
}

// x' = 1 + x(t - 1) - x: every constant history moves, no equilibrium (g = 1, g' = 0).
struct NoEquilibrium {
  static constexpr int d = 1;
  static constexpr bool has_switching = false, affine_in_state = true, is_linear = false, autonomous = true;
  double tau() const { return 1; }
  double period() const { return 1; }
  Vec<1> f(int, double, const Vec<1>& y, const Vec<1>& w) const { return Vec<1>(1 + w[0] - y[0]); }
  Mat<1> A(int, double, const Vec<1>&, const Vec<1>&) const { return Mat<1>::Constant(-1); }
  Mat<1> B(int, double, const Vec<1>&, const Vec<1>&) const { return Mat<1>::Constant(1); }
  Vec<1> initial_state() const { return Vec<1>(0); }
};

// ConstantHistory's SVD-based parts (LAPACK zgesvd in the library) against a system whose root
// and eigenvector are known by hand, and against Eigen's JacobiSVD (an independent SVD):
// A = [[a, -2 b], [b / 2, a]] has the eigenvalues a +- i b with the eigenvector (1, -i / 2) for
// a + i b; with B = beta I and one delay, Delta(i w) = i w I - A - beta e^{-i w tau} I is singular
// when a + i b = i w - beta e^{-i w tau}. The null vector is then (2, -i) / sqrt 5 (its largest
// entry real and positive, the documented phase). 1e-13: the smallest singular value is simple,
// the next ~|b| = O(1) away, so the SVD's vector is good to a few eps |Delta| / gap.
TEST(Equilibrium, NullVectorAndResidualOfAKnownSingularDelta) {
  const double w = 1.3, beta = 0.4, tau = 0.7;
  const cd z = cd(0, w) - beta * std::exp(cd(0, -w * tau));
  ConstantHistory h;
  h.A.resize(2, 2);
  h.A << z.real(), -2 * z.imag(), z.imag() / 2, z.real();
  h.B = beta * Eigen::MatrixXd::Identity(2, 2);
  h.taus = {tau};
  h.f = Eigen::VectorXd::Zero(2);
  const Eigen::VectorXcd c = h.null_vector(cd(0, w));
  ASSERT_EQ(c.size(), 2);
  EXPECT_NEAR(std::abs(c[0] - 2 / std::sqrt(5.0)), 0, 1e-13) << c.transpose();
  EXPECT_NEAR(std::abs(c[1] - cd(0, -1 / std::sqrt(5.0))), 0, 1e-13) << c.transpose();
  EXPECT_LT(h.residual(cd(0, w)), 1e-15);
  // Away from the root: sigma_min(Delta) / (|lambda| + |A|_2 + |B|_2), by Eigen's JacobiSVD
  for (const cd l : {cd(0.1, w), cd(-0.5, 2.0), cd(0.3, 0)}) {
    const double smallest = Eigen::JacobiSVD<Eigen::MatrixXcd>(h.delta(l)).singularValues()(1);
    const double scale = std::abs(l) + Eigen::JacobiSVD<Eigen::MatrixXd>(h.A).singularValues()(0) + beta;
    EXPECT_NEAR(h.residual(l), smallest / scale, 1e-14 * smallest / scale + 1e-16) << l;
    // the vector of the smallest singular value: |Delta c| = sigma_min, |c| = 1
    const Eigen::VectorXcd v = h.null_vector(l);
    EXPECT_NEAR(v.norm(), 1, 1e-14);
    EXPECT_NEAR((h.delta(l) * v).norm(), smallest, 1e-13) << l;
  }
}

TEST(Equilibrium, BadInputAndAModelWithoutEquilibrium) {
  EquilibriumOptions o;
  o.nroots = 0;
  EXPECT_THROW(find_equilibrium(LinearModel(), Vec<1>(0), o), BadInput);
  try {
    find_equilibrium(NoEquilibrium(), Vec<1>(0.5));
    FAIL() << "no equilibrium exists";
  } catch (const NumericalFailure& e) {
    EXPECT_NE(std::string(e.what()).find("singular"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace delayspec

// ---- the branch of equilibria (equilibrium_branch.hpp) ----

namespace delayspec {
namespace {

// The family of a model type made from a parameter: its values and its equilibria at p.
template <class Model, class Make>
EquilibriumFamily family_of(Make make) {
  return {[make](const Eigen::VectorXd& y, double p) { return constant_history(make(p), Vec<Model::d>(y)); },
          [make](const Eigen::VectorXd& guess, double p, int nroots) {
            EquilibriumOptions o;
            o.nroots = nroots;
            return find_equilibrium(make(p), Vec<Model::d>(guess), o);
          },
          nullptr};  // no normal forms here: test_hopf_normal_form.cpp
}

TEST(EquilibriumBranch, MackeyGlassHopfPointInTauIsTheClosedForm) {
  // x* = 1, linearisation x' = a x + b x(t - tau) with a = -gamma, b = beta (2 - n) / 4: at
  // lambda = i omega, omega = sqrt(b^2 - a^2) and cos(omega tau) = -a / b (sin > 0 as -b > 0).
  const double a = -0.1, b = 0.2 * (2 - 10) / 4.0, omega = std::sqrt(b * b - a * a);
  const double tau_H = std::acos(-a / b) / omega;
  const EquilibriumFamily family = family_of<MackeyGlassModel>([](double tau) {
    MackeyGlassParameters p;
    p.tau = p.period = tau;
    return MackeyGlassModel(p);
  });
  EquilibriumBranchOptions o;
  o.from = 3, o.to = 6;
  const EquilibriumBranch branch = continue_equilibrium(family, Vec<1>(1.1), o);
  EXPECT_EQ(branch.end, BranchEnd::to);
  EXPECT_EQ(branch.points.back().parameter, 6);
  ASSERT_EQ(branch.bifurcations.size(), 1u);
  const EquilibriumBifurcation& h = branch.bifurcations[0];
  EXPECT_EQ(h.type, EquilibriumBifurcationType::hopf);
  // located to the default tolerance 1e-10 |to - from| on the exact characteristic function
  EXPECT_NEAR(h.parameter, tau_H, 1e-10);
  EXPECT_NEAR(h.omega, omega, 1e-10);
  EXPECT_NEAR(h.period, 2 * M_PI / omega, 1e-9);
  EXPECT_NEAR(h.state[0], 1, 1e-14);
  EXPECT_LE(h.parameter_bound, 3e-10);
  // stable before, a pair unstable after
  EXPECT_EQ(branch.points.front().equilibrium.unstable, 0);
  EXPECT_EQ(branch.points.back().equilibrium.unstable, 2);
}

// x' = p - x^2 + c (x(t - delay) - x): equilibria x = +-sqrt(p), a fold at p = 0; the root through
// 0 is real (lambda = -2 x - c + c e^{-lambda delay}: at x = 0, lambda = 0).
struct FoldModel {
  static constexpr int d = 1;
  static constexpr bool has_switching = false, affine_in_state = false, is_linear = false, autonomous = true;
  double p = 1, c = 0.5, delay = 1;
  double tau() const { return delay; }
  double period() const { return delay; }
  Vec<1> f(int, double, const Vec<1>& y, const Vec<1>& w) const { return Vec<1>(p - y[0] * y[0] + c * (w[0] - y[0])); }
  Mat<1> A(int, double, const Vec<1>& y, const Vec<1>&) const { return Mat<1>::Constant(-2 * y[0] - c); }
  Mat<1> B(int, double, const Vec<1>&, const Vec<1>&) const { return Mat<1>::Constant(c); }
  Vec<1> initial_state() const { return Vec<1>(1); }
};

TEST(EquilibriumBranch, FoldIsPassedAndLocated) {
  const EquilibriumFamily family = family_of<FoldModel>([](double p) { return FoldModel{p, 0.5}; });
  EquilibriumBranchOptions o;
  o.from = 1, o.to = -1;
  const EquilibriumBranch branch = continue_equilibrium(family, Vec<1>(0.9), o);
  // down the upper branch x = sqrt(p) to the fold, then back up the lower one to p = 1 again
  EXPECT_EQ(branch.end, BranchEnd::from);
  EXPECT_LT(branch.points.back().equilibrium.state[0], -0.9);
  for (const EquilibriumPoint& pt : branch.points)
    EXPECT_NEAR(pt.equilibrium.state[0] * pt.equilibrium.state[0], pt.parameter, 1e-12);
  ASSERT_EQ(branch.bifurcations.size(), 1u);
  const EquilibriumBifurcation& f = branch.bifurcations[0];
  EXPECT_EQ(f.type, EquilibriumBifurcationType::fold);
  EXPECT_NEAR(f.parameter, 0, 2e-10);   // the tolerance, 1e-10 |to - from|
  EXPECT_NEAR(f.state[0], 0, 1e-9);     // the root is linear in x there: as precise as the root
  EXPECT_EQ(f.root.value.imag(), 0);
  EXPECT_EQ(branch.points.front().equilibrium.unstable, 0);
  EXPECT_EQ(branch.points.back().equilibrium.unstable, 1);
}

// x' = p - x^2 + q (x(t - 2) - x) at q = -1.5, down the upper branch x = sqrt(p) from p = 1: near
// p = 0.05 two real roots of c right of the axis (Delta(lambda) = lambda + 2 x + q - q e^{-2 lambda})
// merge into a complex pair, never crossing the axis. Following the pair back onto the two real
// roots took them for "two roots landed on the same root" and ended the branch there (found while
// testing Bogdanov-Takens points); the branch now passes it and reaches its fold at p = 0.
TEST(EquilibriumBranch, TwoRealRootsMergingIntoAPairOffTheAxisAreNoCrossing) {
  const EquilibriumFamily family = family_of<FoldModel>([](double p) { return FoldModel{p, -1.5, 2}; });
  EquilibriumBranchOptions o;
  o.from = 1, o.to = -1;
  const EquilibriumBranch branch = continue_equilibrium(family, Vec<1>(1.0), o);
  EXPECT_EQ(branch.end, BranchEnd::from) << branch.failure;
  // the merge happened on the way: the rightmost root real at some point, complex at another, right of the axis
  bool real_right = false, pair_right = false;
  for (const EquilibriumPoint& pt : branch.points) {
    const CharacteristicRoot& r = pt.equilibrium.roots.front();
    if (pt.equilibrium.state[0] > 0 && r.value.real() > 0) (r.value.imag() == 0 ? real_right : pair_right) = true;
  }
  EXPECT_TRUE(real_right && pair_right);
  ASSERT_EQ(branch.bifurcations.size(), 1u);
  EXPECT_EQ(branch.bifurcations[0].type, EquilibriumBifurcationType::fold);
  EXPECT_NEAR(branch.bifurcations[0].parameter, 0, 2e-10);  // the tolerance, 1e-10 |to - from|
}

// The Lang-Kobayashi laser with delayed optical feedback in real form (issue 61's reproducer),
// E = Ex + i Ey, C = 0:
//
//   E' = (1 + i alpha) Nc E + kappa E(t - tau),   Tc Nc' = P - Nc - (1 + 2 Nc) |E|^2.
//
// Its off state E = 0, Nc = P has the carrier root lambda = -1/Tc exactly (Nc decouples: a
// linear decay) and the roots of lambda = (1 + i alpha) P + kappa e^{-lambda tau} with their
// conjugates. A Hopf point: lambda = i w gives P = -kappa cos(w tau) and
// w = alpha P - kappa sin(w tau) = -kappa (alpha cos(w tau) + sin(w tau)).
struct LangKobayashi {
  static constexpr int d = 3;
  static constexpr bool has_switching = false, affine_in_state = false, is_linear = false, autonomous = true;
  double alpha = 3, kappa = 0.1, P = -0.2, Tc = 20, delay = 2;
  double tau() const { return delay; }
  double period() const { return delay; }
  Vec<3> f(int, double, const Vec<3>& y, const Vec<3>& w) const {
    const double n = y[2], e2 = y[0] * y[0] + y[1] * y[1];
    return Vec<3>(n * y[0] - alpha * n * y[1] + kappa * w[0], n * y[1] + alpha * n * y[0] + kappa * w[1],
                  (P - n - (1 + 2 * n) * e2) / Tc);
  }
  Mat<3> A(int, double, const Vec<3>& y, const Vec<3>&) const {
    const double n = y[2], e2 = y[0] * y[0] + y[1] * y[1];
    Mat<3> a;
    a << n, -alpha * n, y[0] - alpha * y[1],  //
        alpha * n, n, y[1] + alpha * y[0],    //
        -2 * (1 + 2 * n) * y[0] / Tc, -2 * (1 + 2 * n) * y[1] / Tc, (-1 - 2 * e2) / Tc;
    return a;
  }
  Mat<3> B(int, double, const Vec<3>&, const Vec<3>&) const {
    Mat<3> b = Mat<3>::Zero();
    b(0, 0) = b(1, 1) = kappa;
    return b;
  }
  Vec<3> initial_state() const { return Vec<3>(0, 0, P); }
};

// The Hopf points of the off state in P, from w + kappa (alpha cos(w tau) + sin(w tau)) = 0 by
// bisection on a fine grid of w (a reference the engine does not produce).
std::vector<double> lang_kobayashi_hopf_points(const LangKobayashi& m) {
  const auto g = [&](double w) { return w + m.kappa * (m.alpha * std::cos(w * m.delay) + std::sin(w * m.delay)); };
  std::vector<double> points;
  for (double w0 = -5; w0 < 5; w0 += 1e-4) {
    double lo = w0, hi = w0 + 1e-4;
    if ((g(lo) > 0) == (g(hi) > 0)) continue;
    for (int i = 0; i < 200 && hi - lo > 1e-16; ++i)
      ((g(0.5 * (lo + hi)) > 0) == (g(lo) > 0) ? lo : hi) = 0.5 * (lo + hi);
    points.push_back(-m.kappa * std::cos(0.5 * (lo + hi) * m.delay));
  }
  return points;
}

// Delta exactly singular: the carrier root -1/Tc of the off state makes Delta's third row and
// column zero, a zero pivot. Newton's step there is 0 (the root is exact); before issue 61 the
// solve divided by the pivot and the trace was inf - inf = NaN, and the root "did not converge".
TEST(Equilibrium, AnExactlySingularDeltaIsAConvergedRoot) {
  const LangKobayashi m;
  const ConstantHistory h = constant_history(m, m.initial_state());
  EXPECT_EQ(h.newton_step(-1 / m.Tc), 0.0);
  EquilibriumOptions o;
  const CharacteristicRoot root = refined_root(h, -1 / m.Tc, o);
  EXPECT_EQ(root.value, cd(-1 / m.Tc));
  // and the whole computation at that point: every root found, the carrier root among them
  const EquilibriumResult r = find_equilibrium(m, Vec<3>(0, 0, -0.2), o);
  EXPECT_TRUE(std::any_of(r.roots.begin(), r.roots.end(), [&](const CharacteristicRoot& c) {
    return std::abs(c.value - cd(-1 / m.Tc)) < 1e-15;
  }));
}

// Near a double real root the N = 100 discretisation gives two real roots where the exact ones are
// a complex pair: x' = 1.5 x - 1.648722 x(t - 1) (the double root 1/2 at b = -e^{1/2} =
// -1.64872127...), exact pair 0.50000029489509261 +- 0.00094057707055736 i (mpmath, 40 digits).
// Newton from the real start stayed on the axis: "did not converge", exit 3. Now the pair, to its
// bound (the bound's floor is rounding: the root is ill-conditioned only at the double root itself).
TEST(Equilibrium, AComplexPairTheDiscretisationSplitIntoTwoRealRootsIsFound) {
  const LinearModel model({.a = 1.5, .b = -1.648722, .tau = 1, .period = 1});
  EquilibriumOptions o;
  o.nroots = 2;
  const EquilibriumResult r = find_equilibrium(model, Vec<1>(0.0), o);
  ASSERT_EQ(r.roots.size(), 2u);
  const cd exact(0.50000029489509261, 0.00094057707055736);
  for (const CharacteristicRoot& root : r.roots) {
    const cd e = root.value.imag() > 0 ? exact : std::conj(exact);
    EXPECT_LE(std::abs(root.value - e), std::max(root.error_bound, 1e-15)) << root.value;
    EXPECT_LE(std::abs(root.value - e), 1e-12) << root.value;
  }
  EXPECT_EQ(r.unstable, 2);
}

// Issue 61's reproducers: from the default steps (range / 50, growing to range / 10), each Hopf
// point of the closed form is found once, as a Hopf point, and nothing else. Before: kappa = 0.1
// ended in "did not converge (last step -nan)"; kappa = 0.3 printed a branch point at P = -0.1279
// (the crossing root refined onto the carrier root, a bracket around no root on the axis).
// 1e-10: the location's tolerance, 1e-10 |to - from| (<= 1.5e-10), on the exact characteristic
// function.
TEST(EquilibriumBranch, LangKobayashiHopfPointIsTheClosedFormAndNothingElse) {
  for (const auto& [kappa, from, to] : {std::tuple{0.1, -0.2, 0.1}, std::tuple{0.3, -0.5, 1.0}}) {
    SCOPED_TRACE("kappa = " + std::to_string(kappa));
    LangKobayashi base;
    base.kappa = kappa;
    const std::vector<double> exact = lang_kobayashi_hopf_points(base);
    ASSERT_EQ(exact.size(), 1u);  // one w solves it for these kappa (|kappa tau sqrt(1 + alpha^2)| < 1)
    const EquilibriumFamily family = family_of<LangKobayashi>([base](double P) {
      LangKobayashi m = base;
      m.P = P;
      return m;
    });
    EquilibriumBranchOptions o;
    o.from = from, o.to = to;
    const EquilibriumBranch branch = continue_equilibrium(family, Vec<3>(0, 0, from), o);
    ASSERT_EQ(branch.end, BranchEnd::to) << branch.failure;
    ASSERT_EQ(branch.bifurcations.size(), 1u);
    const EquilibriumBifurcation& h = branch.bifurcations[0];
    EXPECT_EQ(h.type, EquilibriumBifurcationType::hopf);
    EXPECT_NEAR(h.parameter, exact[0], 1.5e-10);
    EXPECT_LT(std::abs(h.root.value.real()), 1e-9);
    EXPECT_EQ(branch.points.front().equilibrium.unstable, 0);
    EXPECT_EQ(branch.points.back().equilibrium.unstable, 2);
  }
}

// Mackey-Glass at x* = 1 over tau in [3, 60] (issue 61): its Hopf points are
// tau_k = (arccos(-gamma / b) + 2 pi k) / omega, omega = sqrt(b^2 - gamma^2) = sqrt(0.15), b = -0.4:
// four of them, each adding a pair, so that at tau = 53.4 six roots are already unstable. Before:
// with nroots = 6 tracked, one printed at tau = 23.616 with omega = 0.105 (another root's) and the
// fourth missed. The tracked roots grow with the count (kRootMargin), a step with two crossings
// is halved, and the location's checks hold. 2e-9: the tolerance 1e-10 |to - from| = 5.7e-9 is
// the bracket's width; measured within 1e-9.
TEST(EquilibriumBranch, MackeyGlassFourHopfPointsOverALongRangeInTau) {
  const double a = -0.1, b = -0.4, omega = std::sqrt(b * b - a * a);
  const EquilibriumFamily family = family_of<MackeyGlassModel>([](double tau) {
    MackeyGlassParameters p;
    p.tau = p.period = tau;
    return MackeyGlassModel(p);
  });
  EquilibriumBranchOptions o;
  o.from = 3, o.to = 60;
  const EquilibriumBranch branch = continue_equilibrium(family, Vec<1>(1.1), o);
  ASSERT_EQ(branch.end, BranchEnd::to) << branch.failure;
  ASSERT_EQ(branch.bifurcations.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    const EquilibriumBifurcation& h = branch.bifurcations[static_cast<size_t>(k)];
    EXPECT_EQ(h.type, EquilibriumBifurcationType::hopf);
    EXPECT_NEAR(h.parameter, (std::acos(-a / b) + 2 * M_PI * k) / omega, 5.7e-9) << k;
    EXPECT_NEAR(h.omega, omega, 1e-9) << k;
  }
  EXPECT_EQ(branch.points.back().equilibrium.unstable, 8);
}

}  // namespace
}  // namespace delayspec
