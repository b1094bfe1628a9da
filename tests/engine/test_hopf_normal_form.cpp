// The first Lyapunov coefficient of Hopf points (hopf_normal_form.hpp), against values the engine
// does not produce:
//  * Wright's equation y' = -r y(t - 1) (1 + y) at r = pi/2 (Hutchinson's x' = r x (1 - x(t - 1))
//    at x* = 1): its orbit's amplitude is known in closed form (Chow and Mallet-Paret 1977),
//    y = sqrt(40 (r - pi/2) / (3 pi - 2)) cos(pi t / 2) + ..., which with
//    |z|^2 = -Re lambda'(r) (r - pi/2) / Re c1, amplitude 2 |z| (|v| = 1, d = 1) and
//    Re lambda'(pi/2) = (pi/2) / (1 + pi^2/4) gives l1 = Re c1 / omega = -(3 pi - 2) / (10 (1 + pi^2/4));
//  * the cubic c y(t - 1)^3 added: it acts through C alone, C(Phi, Phi, conj Phi) = 6 c |Phi_1|^2 Phi_1
//    = -6 c i (v = 1, Phi_1 = e^{-i pi/2}), and conj(u) = 1 / Delta'(i pi/2) = 1 / (1 + i pi/2)
//    (Delta' = 1 - r e^{-i omega}), so it adds -3 c / (1 + pi^2/4) to l1: c = -(3 pi - 2) / 30 makes the
//    Hopf point degenerate (l1 = 0), a larger c supercritical, a smaller one subcritical;
//  * Mackey-Glass and the Lang-Kobayashi laser: scripts/hopf_normal_form_reference.py, which locates
//    the Hopf points itself and differentiates f at 40 digits with mpmath.
// The bars: every l1 is within its l1_bound of the reference, and the bound is tight (a polynomial
// f leaves rounding only: 1e-11 relative; Mackey-Glass's x^10 / (1 + x^10) differences of the
// Jacobian: measured 4e-10 relative, asserted 1e-7 so that the bar stays useful).
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "delayspec/equilibrium.hpp"
#include "delayspec/equilibrium_boundary.hpp"
#include "delayspec/equilibrium_branch.hpp"
#include "delayspec/hopf_normal_form.hpp"
#include "delayspec/model_linear.hpp"
#include "delayspec/model_mackey_glass.hpp"

namespace delayspec {
namespace {

using std::numbers::pi;

// y' = -r y(t - 1) (1 + y) + c y(t - 1)^3, equilibrium 0
struct WrightCubic {
  static constexpr int d = 1;
  static constexpr bool has_switching = false, affine_in_state = false, is_linear = false, autonomous = true;
  double r = pi / 2, c = 0;
  double tau() const { return 1; }
  double period() const { return 1; }
  Vec<1> f(int, double, const Vec<1>& y, const Vec<1>& w) const {
    return Vec<1>(-r * w[0] * (1 + y[0]) + c * w[0] * w[0] * w[0]);
  }
  Mat<1> A(int, double, const Vec<1>&, const Vec<1>& w) const { return Mat<1>::Constant(-r * w[0]); }
  Mat<1> B(int, double, const Vec<1>& y, const Vec<1>& w) const {
    return Mat<1>::Constant(-r * (1 + y[0]) + 3 * c * w[0] * w[0]);
  }
  Vec<1> initial_state() const { return Vec<1>(0.1); }
};

// The model's J = [A B] on any history: what ModelAnalyses::jacobian_at gives the scene
template <class Model>
JacobianAt jacobian_of(const Model& m) {
  return [m](const Eigen::VectorXd& y, const Eigen::VectorXd& w) {
    constexpr int D = Model::d;
    const auto A = m.A(1, 0.0, Vec<D>(y), Vec<D>(w));
    const auto B = m.B(1, 0.0, Vec<D>(y), Vec<D>(w));
    Eigen::MatrixXd J(D, 2 * D);  // entry by entry: a 1 x 1 block copy trips GCC 12's -Warray-bounds
    for (int c = 0; c < 2 * D; ++c)
      for (int r = 0; r < D; ++r) J(r, c) = c < D ? A(r, c) : B(r, c - D);
    return J;
  };
}

HopfNormalForm wright_normal_form(double c) {
  const WrightCubic m{pi / 2, c};
  CharacteristicRoot root;
  root.value = {0, pi / 2};
  root.error_bound = 4e-16;
  return hopf_normal_form(jacobian_of(m), constant_history(m, Vec<1>(0)), Vec<1>(0), root);
}

TEST(HopfNormalForm, WrightsEquationIsTheClosedForm) {
  const double exact = -(3 * pi - 2) / (10 * (1 + pi * pi / 4));
  const HopfNormalForm n = wright_normal_form(0);
  EXPECT_TRUE(n.note.empty()) << n.note;
  EXPECT_LE(std::abs(n.l1 - exact), n.l1_bound) << n.l1 - exact;
  EXPECT_LE(n.l1_bound, 1e-11 * std::abs(exact));
  EXPECT_EQ(n.criticality, HopfCriticality::supercritical);
  EXPECT_NEAR(std::abs(n.eigenvector[0]), 1, 1e-15);
}

TEST(HopfNormalForm, TheCubicTermDecidesTheSignAndZeroIsDegenerate) {
  // the cubic alone: the quadratic part of Wright's equation is there too, and adds its l1
  const double quadratic = -(3 * pi - 2) / (10 * (1 + pi * pi / 4));
  for (const double c : {1.0, -1.0, -(3 * pi - 2) / 30}) {
    SCOPED_TRACE("c = " + std::to_string(c));
    const double exact = quadratic - 3 * c / (1 + pi * pi / 4);
    const HopfNormalForm n = wright_normal_form(c);
    EXPECT_LE(std::abs(n.l1 - exact), n.l1_bound) << n.l1 - exact;
    EXPECT_LE(n.l1_bound, 1e-11);
    EXPECT_EQ(n.criticality, exact > 1e-10   ? HopfCriticality::subcritical
                             : exact < -1e-10 ? HopfCriticality::supercritical
                                              : HopfCriticality::degenerate);
  }
}

template <class Model, class Make>
EquilibriumFamily normal_form_family(Make make) {
  return {[make](const Eigen::VectorXd& y, double p) { return constant_history(make(p), Vec<Model::d>(y)); },
          [make](const Eigen::VectorXd& guess, double p, int nroots) {
            EquilibriumOptions o;
            o.nroots = nroots;
            return find_equilibrium(make(p), Vec<Model::d>(guess), o);
          },
          [make](const Eigen::VectorXd& y, const Eigen::VectorXd& w, double p) { return jacobian_of(make(p))(y, w); }};
}

// Along a branch: every Hopf point gets its l1 (the first two of Mackey-Glass in tau, references
// from scripts/hopf_normal_form_reference.py).
TEST(HopfNormalForm, MackeyGlassHopfPointsAlongTheBranchAreTheReference) {
  const EquilibriumFamily family = normal_form_family<MackeyGlassModel>([](double tau) {
    MackeyGlassParameters p;
    p.tau = p.period = tau;
    return MackeyGlassModel(p);
  });
  EquilibriumBranchOptions o;
  o.from = 3, o.to = 22;
  const EquilibriumBranch branch = continue_equilibrium(family, Vec<1>(1.1), o);
  ASSERT_EQ(branch.end, BranchEnd::to) << branch.failure;
  ASSERT_EQ(branch.bifurcations.size(), 2u);
  const double reference[] = {-13.342516550137967989, -3.940663596488831527};
  for (int k = 0; k < 2; ++k) {
    const EquilibriumBifurcation& h = branch.bifurcations[static_cast<size_t>(k)];
    ASSERT_TRUE(h.normal_form.has_value());
    const HopfNormalForm& n = *h.normal_form;
    EXPECT_LE(std::abs(n.l1 - reference[k]), n.l1_bound) << k << ": " << n.l1 - reference[k];
    EXPECT_LE(n.l1_bound, 1e-7 * std::abs(reference[k])) << k;
    EXPECT_EQ(n.criticality, HopfCriticality::supercritical);
  }
}

// A family without a Jacobian gives no normal form (and the branch is as before)
TEST(HopfNormalForm, NoJacobianNoNormalForm) {
  EquilibriumFamily family = normal_form_family<MackeyGlassModel>([](double tau) {
    MackeyGlassParameters p;
    p.tau = p.period = tau;
    return MackeyGlassModel(p);
  });
  family.jacobian = nullptr;
  EquilibriumBranchOptions o;
  o.from = 3, o.to = 6;
  const EquilibriumBranch branch = continue_equilibrium(family, Vec<1>(1.1), o);
  ASSERT_EQ(branch.bifurcations.size(), 1u);
  EXPECT_FALSE(branch.bifurcations[0].normal_form.has_value());
}

// A zero root beside the pair (a zero-Hopf point): Delta(0) singular, no l1, said so.
// y1' = -r y1(t - 1) (1 + y2), y2' = y1 y1(t-1): the second component's root is 0 for every r.
struct ZeroHopf {
  static constexpr int d = 2;
  static constexpr bool has_switching = false, affine_in_state = false, is_linear = false, autonomous = true;
  double r = pi / 2;
  double tau() const { return 1; }
  double period() const { return 1; }
  Vec<2> f(int, double, const Vec<2>& y, const Vec<2>& w) const {
    return Vec<2>(-r * w[0] * (1 + y[1]), y[0] * w[0]);
  }
  Mat<2> A(int, double, const Vec<2>&, const Vec<2>& w) const {
    Mat<2> a;
    a << 0, -r * w[0], w[0], 0;
    return a;
  }
  Mat<2> B(int, double, const Vec<2>& y, const Vec<2>&) const {
    Mat<2> b;
    b << -r * (1 + y[1]), 0, y[0], 0;
    return b;
  }
  Vec<2> initial_state() const { return Vec<2>(0, 0); }
};

TEST(HopfNormalForm, AZeroHopfPointHasNoFirstLyapunovCoefficient) {
  const ZeroHopf m;
  CharacteristicRoot root;
  root.value = {0, pi / 2};
  const Vec<2> zero = Vec<2>::Zero();
  const HopfNormalForm n = hopf_normal_form(jacobian_of(m), constant_history(m, zero), zero, root);
  EXPECT_EQ(n.criticality, HopfCriticality::degenerate);
  EXPECT_TRUE(std::isnan(n.l1));
  EXPECT_NE(n.note.find("zero-Hopf"), std::string::npos) << n.note;
}

// ---- Hopf curves in two parameters (equilibrium_boundary.hpp) ----

template <class Model, class Make>
EquilibriumFamily2 family_in_two(Make make) {
  return {[make](const Eigen::VectorXd& s, double x, double y) { return constant_history(make(x, y), Vec<Model::d>(s)); },
          [make](const Eigen::VectorXd& guess, double x, double y, int nroots) {
            EquilibriumOptions o;
            o.nroots = nroots;
            const Model m = make(x, y);
            return find_equilibrium(m, guess.size() ? Vec<Model::d>(guess) : m.initial_state(), o);
          },
          [make](const Eigen::VectorXd& s, const Eigen::VectorXd& w, double x, double y) {
            return jacobian_of(make(x, y))(s, w);
          }};
}

// x' = a x + b x(t - 1) in (a, b)
EquilibriumFamily2 linear_in_a_b() {
  return family_in_two<LinearModel>([](double a, double b) {
    LinearParameters p;
    p.a = a, p.b = b;
    return LinearModel(p);
  });
}

// x' = a x + b x(t - 1) in (a, b): i omega = a + b e^{-i omega} gives the curve
// a = omega cot omega, b = -omega / sin omega (0 < omega < pi). Every point the tracer returns is
// on it to the locator's accuracy: from the point's omega, a and b agree with the closed form to
// 1e-9 (the points are corrected to 1e-10 of the range in the scaled plane, and the root to 1e-12).
TEST(HopfCurves, LinearHopfCurveIsTheClosedForm) {
  HopfCurveOptions o;
  o.boundary.x_from = -1, o.boundary.x_to = 0.9, o.boundary.y_from = -0.5, o.boundary.y_to = -3;
  const HopfCurves r = hopf_curves(linear_in_a_b(), Eigen::VectorXd(), o);
  ASSERT_EQ(r.curves.size(), 1u);
  const HopfCurve& c = r.curves[0];
  EXPECT_EQ(c.end, BoundaryEnd::to) << c.note;
  ASSERT_GE(c.points.size(), 10u);
  EXPECT_EQ(c.points.front().x, -1);
  EXPECT_NEAR(c.points.back().x, 0.9, 1e-12);
  for (const HopfCurvePoint& p : c.points) {
    const double w = p.root.value.imag();
    EXPECT_NEAR(p.x, w / std::tan(w), 1e-9) << w;
    EXPECT_NEAR(p.y, -w / std::sin(w), 1e-9) << w;
    // a linear model's Hopf points are degenerate: l1 = 0 exactly
    ASSERT_TRUE(p.normal_form.has_value());
    EXPECT_EQ(p.normal_form->criticality, HopfCriticality::degenerate);
  }
  EXPECT_TRUE(c.codim2.empty());
}

// The same curve runs into its Bogdanov-Takens point (a, b) = (1, -1) (omega -> 0 as a -> 1): the
// curve ends there as a codim-2 end, named, not as a failure; its last point within 1e-4 of it
// (the tracer halves its step towards it down to step_min 1e-6 of the range).
TEST(HopfCurves, AHopfCurveEndsAtItsBogdanovTakensPoint) {
  HopfCurveOptions o;
  o.boundary.x_from = -1, o.boundary.x_to = 1.2, o.boundary.y_from = -0.5, o.boundary.y_to = -3;
  const HopfCurves r = hopf_curves(linear_in_a_b(), Eigen::VectorXd(), o);
  ASSERT_EQ(r.curves.size(), 1u);
  const HopfCurve& c = r.curves[0];
  EXPECT_EQ(c.end, BoundaryEnd::codim2) << c.note;
  EXPECT_NE(c.note.find("Bogdanov-Takens"), std::string::npos) << c.note;
  EXPECT_NEAR(c.points.back().x, 1, 1e-4);
  EXPECT_NEAR(c.points.back().y, -1, 1e-4);
}

// Wright's equation with the cubic c y(t - 1)^3 in (c, r): the Hopf curve is r = pi/2 for every c
// (the linearisation does not see c), and l1 = -(3 pi - 2) / (10 (1 + pi^2/4)) - 3 c / (1 + pi^2/4)
// (the closed forms above) vanishes at c* = -(3 pi - 2) / 30: the generalised Hopf point, located
// on the curve within its bound, and the bound small (l1's bar is rounding here: 1e-8 leaves
// the location's tolerance and l1_bound / |dl1/dc| ~ 1e-13 far behind).
TEST(HopfCurves, WrightCubicGeneralisedHopfPointIsTheClosedForm) {
  HopfCurveOptions o;
  o.boundary.x_from = -1, o.boundary.x_to = 1, o.boundary.y_from = 1, o.boundary.y_to = 2;
  const HopfCurves r = hopf_curves(family_in_two<WrightCubic>([](double c, double rr) { return WrightCubic{rr, c}; }),
                                   Vec<1>(0.1), o);
  ASSERT_EQ(r.curves.size(), 1u);
  const HopfCurve& c = r.curves[0];
  EXPECT_EQ(c.end, BoundaryEnd::to) << c.note;
  for (const HopfCurvePoint& p : c.points) EXPECT_NEAR(p.y, pi / 2, 1e-10);
  ASSERT_EQ(c.codim2.size(), 1u);
  const HopfCodim2Point& gh = c.codim2[0];
  EXPECT_EQ(gh.kind, HopfCodim2Kind::generalised_hopf);
  const double exact = -(3 * pi - 2) / 30;
  EXPECT_LE(std::abs(gh.x - exact), gh.bound) << gh.x - exact;
  EXPECT_LE(gh.bound, 1e-8);
  EXPECT_NEAR(gh.y, pi / 2, 1e-10);
  EXPECT_NEAR(gh.omega, pi / 2, 1e-10);
  // subcritical on the left of c*, supercritical on the right
  EXPECT_EQ(c.points.front().normal_form->criticality, HopfCriticality::subcritical);
  EXPECT_EQ(c.points.back().normal_form->criticality, HopfCriticality::supercritical);
}

// Two Wright-like components side by side, the first in p1 with delay 1 (its Hopf curve p1 = pi/2,
// omega = pi/2), the second in p2: with `delayed`, y2' = -p2 y2(t - 2) (1 + y2), whose pair reaches
// the axis at p2 = pi/4 (i w = -p2 e^{-2 i w}: 2 w = pi/2, p2 = w = pi/4); otherwise
// y2' = (p2 - 1) y2 - y2^3, whose real root p2 - 1 crosses 0 at p2 = 1.
struct TwoComponents {
  static constexpr int d = 2, delay_count = 2;
  static constexpr bool has_switching = false, affine_in_state = false, is_linear = false, autonomous = true;
  double p1 = 1.5, p2 = 0.5;
  bool delayed = true;
  std::array<double, 2> delays() const { return {1, 2}; }
  double tau() const { return 2; }
  double period() const { return 2; }
  Vec<2> f(int, double, const Vec<2>& y, const Vec<4>& z) const {
    return Vec<2>(-p1 * z[0] * (1 + y[0]), delayed ? -p2 * z[3] * (1 + y[1]) : (p2 - 1) * y[1] - y[1] * y[1] * y[1]);
  }
  Mat<2> A(int, double, const Vec<2>& y, const Vec<4>& z) const {
    Mat<2> a = Mat<2>::Zero();
    a(0, 0) = -p1 * z[0];
    a(1, 1) = delayed ? -p2 * z[3] : (p2 - 1) - 3 * y[1] * y[1];
    return a;
  }
  RectMat<2, 4> B(int, double, const Vec<2>& y, const Vec<4>&) const {
    RectMat<2, 4> b = RectMat<2, 4>::Zero();
    b(0, 0) = -p1 * (1 + y[0]);
    if (delayed) b(1, 3) = -p2 * (1 + y[1]);
    return b;
  }
  Vec<2> initial_state() const { return Vec<2>(0.1, 0.1); }
};

// Along the Hopf curve p1 = pi/2 in (p2, p1), the second component's root reaches the axis: a
// double Hopf point at p2 = pi/4 (second pair i pi/4) or a zero-Hopf point at p2 = 1, each at its
// closed form within its bound (the root is refined on c: the bound is the tolerance's, <= 1e-8).
TEST(HopfCurves, DoubleAndZeroHopfPointsAreTheClosedForms) {
  for (const bool delayed : {true, false}) {
    SCOPED_TRACE(delayed ? "double Hopf" : "zero-Hopf");
    const auto make = [delayed](double p2, double p1) { return TwoComponents{p1, p2, delayed}; };
    const EquilibriumFamily2 family{
        [make](const Eigen::VectorXd& s, double x, double y) { return constant_history(make(x, y), Vec<2>(s)); },
        [make](const Eigen::VectorXd& guess, double x, double y, int nroots) {
          EquilibriumOptions o;
          o.nroots = nroots;
          return find_equilibrium(make(x, y), Vec<2>(guess), o);
        },
        [make](const Eigen::VectorXd& s, const Eigen::VectorXd& w, double x, double y) {
          const TwoComponents m = make(x, y);
          Eigen::MatrixXd J(2, 6);
          J << m.A(1, 0.0, Vec<2>(s), Vec<4>(w)), m.B(1, 0.0, Vec<2>(s), Vec<4>(w));
          return J;
        }};
    HopfCurveOptions o;
    o.boundary.x_from = 0.5, o.boundary.x_to = 1.5, o.boundary.y_from = 1, o.boundary.y_to = 2;
    const HopfCurves r = hopf_curves(family, Vec<2>(0.01, 0.01), o);
    ASSERT_GE(r.curves.size(), 1u);
    const HopfCurve& c = r.curves[0];
    for (const HopfCurvePoint& p : c.points) EXPECT_NEAR(p.y, pi / 2, 1e-10);
    ASSERT_EQ(c.codim2.size(), 1u) << (c.notes.empty() ? "" : c.notes[0]);
    const HopfCodim2Point& h = c.codim2[0];
    EXPECT_EQ(h.kind, delayed ? HopfCodim2Kind::double_hopf : HopfCodim2Kind::zero_hopf);
    const double exact = delayed ? pi / 4 : 1;
    EXPECT_LE(std::abs(h.x - exact), h.bound) << h.x - exact;
    EXPECT_LE(h.bound, 1e-8);
    EXPECT_NEAR(h.omega, pi / 2, 1e-9);
    EXPECT_NEAR(std::abs(h.second_root.imag()), delayed ? pi / 4 : 0, 1e-9);
  }
}

// x' = p + q x - x^3 + c (x(t - 1) - x): J = A + B = q - 3 x^2 (the delay cancels at a constant
// history), so the equilibria fold where q = 3 x^2, p = -2 x^3: the two fold curves of a cusp,
// p = -+2 (q / 3)^{3/2}. The branch in p at q = 0.5 passes both folds (lower branch up, middle
// back, upper up); each starts a curve traced on the extended system, every point of which has its
// equilibrium x on the closed form to 1e-9 (Newton's tolerance 1e-10 in the scaled plane, a
// Jacobian by differences: the solution is exact to the tolerance).
struct CuspModel {
  static constexpr int d = 1;
  static constexpr bool has_switching = false, affine_in_state = false, is_linear = false, autonomous = true;
  double p = -2, q = 0.5, c = 0.5;
  double tau() const { return 1; }
  double period() const { return 1; }
  Vec<1> f(int, double, const Vec<1>& y, const Vec<1>& w) const {
    return Vec<1>(p + q * y[0] - y[0] * y[0] * y[0] + c * (w[0] - y[0]));
  }
  Mat<1> A(int, double, const Vec<1>& y, const Vec<1>&) const { return Mat<1>::Constant(q - 3 * y[0] * y[0] - c); }
  Mat<1> B(int, double, const Vec<1>&, const Vec<1>&) const { return Mat<1>::Constant(c); }
  Vec<1> initial_state() const { return Vec<1>(-1.4); }
};

TEST(FoldCurves, TheCuspsTwoFoldCurvesAreTheClosedForm) {
  HopfCurveOptions o;
  o.boundary.x_from = 0.5, o.boundary.x_to = 2, o.boundary.y_from = -2, o.boundary.y_to = 2;
  const FoldCurves r = fold_curves(family_in_two<CuspModel>([](double q, double p) { return CuspModel{p, q, 0.5}; }),
                                   Vec<1>(-1.4), o);
  ASSERT_EQ(r.curves.size(), 2u);
  for (const FoldCurve& c : r.curves) {
    EXPECT_EQ(c.end, BoundaryEnd::to) << c.note;
    ASSERT_GE(c.points.size(), 5u);
    EXPECT_NEAR(c.points.front().x, 0.5, 1e-9);
    EXPECT_NEAR(c.points.back().x, 2, 1e-9);
    for (const FoldCurvePoint& p : c.points) {
      const double x = p.state[0];
      EXPECT_NEAR(p.x, 3 * x * x, 1e-9);
      EXPECT_NEAR(p.y, -2 * x * x * x, 1e-9);
    }
  }
  // one curve on each side: p > 0 on the lower branch's fold (x < 0), p < 0 on the upper's
  EXPECT_LT(r.curves[0].points.back().y * r.curves[1].points.back().y, 0);
}

// x' = p - x^2 + q (x(t - 2) - x): equilibria x = +-sqrt p, J = A + B = -2 x, so the equilibria fold
// at x = 0 on the line p = 0 for every q; there Delta(lambda) = lambda + q - q e^{-2 lambda}, whose
// Delta'(0) = 1 + 2 q vanishes at q = -1/2: the zero root is double, the Bogdanov-Takens point
// (q, p) = (-1/2, 0). The fold curve traced in q from 0.5 to -1.5 carries exactly that one point,
// within its bound, and the bound is the location's tolerance (1e-10 of the ranges), not more.
// (It starts at q = 0.5, where c has a single real root for every x: from q = -1.5 the branch of
// equilibria in p meets two real roots merging into a complex pair at p = 0.05 and ends there.)
struct TakensModel {
  static constexpr int d = 1;
  static constexpr bool has_switching = false, affine_in_state = false, is_linear = false, autonomous = true;
  double p = 1, q = 0.5;
  double tau() const { return 2; }
  double period() const { return 2; }
  Vec<1> f(int, double, const Vec<1>& y, const Vec<1>& w) const {
    return Vec<1>(p - y[0] * y[0] + q * (w[0] - y[0]));
  }
  Mat<1> A(int, double, const Vec<1>& y, const Vec<1>&) const { return Mat<1>::Constant(-2 * y[0] - q); }
  Mat<1> B(int, double, const Vec<1>&, const Vec<1>&) const { return Mat<1>::Constant(q); }
  Vec<1> initial_state() const { return Vec<1>(1); }
};

TEST(FoldCurves, ABogdanovTakensPointIsLocatedOnItsFoldCurve) {
  HopfCurveOptions o;
  o.boundary.x_from = 0.5, o.boundary.x_to = -1.5, o.boundary.y_from = 1, o.boundary.y_to = -1;
  const FoldCurves r =
      fold_curves(family_in_two<TakensModel>([](double q, double p) { return TakensModel{p, q}; }), Vec<1>(1), o);
  ASSERT_EQ(r.curves.size(), 1u) << (r.notes.empty() ? "" : r.notes[0]);
  const FoldCurve& c = r.curves[0];
  EXPECT_EQ(c.end, BoundaryEnd::to) << c.note;
  for (const FoldCurvePoint& p : c.points) EXPECT_NEAR(p.y, 0, 1e-9);
  ASSERT_EQ(c.codim2.size(), 1u) << (c.notes.empty() ? "" : c.notes[0]);
  const FoldCodim2Point& bt = c.codim2[0];
  EXPECT_EQ(bt.kind, FoldCodim2Kind::bogdanov_takens);
  EXPECT_LE(std::abs(bt.x + 0.5), bt.bound) << bt.x + 0.5;
  EXPECT_LE(bt.bound, 1e-8);
  EXPECT_NEAR(bt.y, 0, 1e-9);
  EXPECT_NEAR(bt.state[0], 0, 1e-6);  // x = sqrt p: the equilibrium's error is the root of p's
}

// The cusp's fold curves away from the cusp (above) have no codim-2 point: Delta'(0) = 1 + c = 1.5
// everywhere, and F'' = -6 x is not 0 on them (x^2 = q / 3 >= 1/6).
TEST(FoldCurves, NoCodim2PointWhereTheZeroRootStaysSimpleAndTheFoldQuadratic) {
  HopfCurveOptions o;
  o.boundary.x_from = 0.5, o.boundary.x_to = 2, o.boundary.y_from = -2, o.boundary.y_to = 2;
  const FoldCurves r = fold_curves(family_in_two<CuspModel>([](double q, double p) { return CuspModel{p, q, 0.5}; }),
                                   Vec<1>(-1.4), o);
  ASSERT_EQ(r.curves.size(), 2u);
  for (const FoldCurve& c : r.curves) EXPECT_TRUE(c.codim2.empty());
}

// Through the cusp: q from 1 down to -1. The two folds of the branch in p at q = 1 are the ends of
// one curve, q = 3 x^2, p = -2 x^3, through (0, 0), where F''(x) = -6 x (F(x) = p + q x - x^3, the
// delay cancelling at a constant history) changes sign: the cusp point, within its bound of the
// closed form (0, 0), and no Bogdanov-Takens point (Delta'(0) = 1.5).
TEST(FoldCurves, TheCuspPointIsLocatedWhereTheTwoFoldsMeet) {
  HopfCurveOptions o;
  o.boundary.x_from = 1, o.boundary.x_to = -1, o.boundary.y_from = 2, o.boundary.y_to = -2;
  const FoldCurves r = fold_curves(family_in_two<CuspModel>([](double q, double p) { return CuspModel{p, q, 0.5}; }),
                                   Vec<1>(-1.4), o);
  ASSERT_EQ(r.curves.size(), 1u) << (r.notes.empty() ? "" : r.notes[0]);
  const FoldCurve& c = r.curves[0];
  ASSERT_EQ(c.codim2.size(), 1u) << (c.notes.empty() ? "" : c.notes[0]);
  const FoldCodim2Point& cusp = c.codim2[0];
  EXPECT_EQ(cusp.kind, FoldCodim2Kind::cusp);
  EXPECT_LE(std::max(std::abs(cusp.x), std::abs(cusp.y)), cusp.bound) << cusp.x << ", " << cusp.y;
  EXPECT_LE(cusp.bound, 1e-8);
}

}  // namespace
}  // namespace delayspec
