// ProblemFamily (problem_family.hpp) through the public headers alone, no scene: a family of the
// linear model x' = a x + b x(t - tau) written here as a C++ user writes one, its members, its
// refusals as outcomes, a branch continued through it that is, bit for bit, the branch of the
// same model continued through the template with the same doubles, and a stability boundary in
// (a, b) (boundary_diagram.hpp) against the exact curve of the characteristic equation.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "delayspec/boundary_diagram.hpp"
#include "delayspec/builtin_analyses.hpp"
#include "delayspec/continuation.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/family_equilibria.hpp"
#include "delayspec/problem_family.hpp"

using namespace delayspec;

namespace {

// tau = 2 pi / (3 sqrt 3): x' = -x + b x(t - tau) has the roots +-i sqrt 3 at b = -2 (i sqrt 3 =
// -1 - 2 exp(-i 2 pi / 3)), a Neimark-Sacker point of the map over T = tau (test_continuation.cpp).
const double kTau = 2 * std::numbers::pi / (3 * std::sqrt(3.0));

// Parameters (a, b, tau); the map's period follows tau.
class LinearFamily final : public ProblemFamily {
 public:
  const std::vector<std::string>& parameter_names() const override { return names_; }
  const std::vector<double>& base_values() const override { return base_; }
  FamilyMember make(const std::vector<double>& v) const override {
    if (v.size() != 3) throw std::invalid_argument("LinearFamily: three values");
    try {
      return {builtin_analyses(LinearModel({v[0], v[1], v[2], v[2]})), ""};
    } catch (const BadInput& e) {  // the model's own checks
      return {nullptr, e.what()};
    }
  }

 private:
  std::vector<std::string> names_ = {"a", "b", "tau"};
  std::vector<double> base_ = {-1, -1.5, kTau};
};

MapSettings map_at(int N) {
  MapSettings map;
  map.N = N;
  return map;
}

}  // namespace

TEST(ProblemFamily, MembersByNameAndRefusalsAsOutcomes) {
  const auto family = std::make_shared<const LinearFamily>();
  EXPECT_EQ(family->index_of("b"), 1);
  EXPECT_EQ(family->index_of("N"), -1);
  EXPECT_EQ(family->with(2, 2.5), (std::vector<double>{-1, -1.5, 2.5}));
  EXPECT_THROW(family->with(3, 1.0), std::invalid_argument);

  const FamilyMember member = family->at(family->with(2, 2.5), map_at(50));
  ASSERT_TRUE(member) << member.rejected;
  EXPECT_EQ(member.analyses->tau(), 2.5);
  EXPECT_EQ(member.analyses->period(), 2.5);

  // A delay the model refuses: an outcome with the model's reason, no exception
  const FamilyMember refused = family->at(family->with(2, -1.0), map_at(50));
  EXPECT_FALSE(refused);
  EXPECT_NE(refused.rejected.find("tau"), std::string::npos) << refused.rejected;
  // Along a parameter (continuation's AnalysesAt) the same refusal is the BadInput that ends a branch
  const AnalysesAt along = analyses_along(family, family->base_values(), 2, map_at(50));
  EXPECT_EQ(along(1.5)->tau(), 1.5);
  try {
    along(-1.0);
    ADD_FAILURE() << "a refused value must throw";
  } catch (const BadInput& e) {
    EXPECT_EQ(std::string(e.what()), refused.rejected);
  }
}

TEST(ProblemFamily, ABranchThroughTheFamilyIsTheTemplatesBranchBitForBit) {
  // The library's continuation through a family (what continue and boundary do) and through
  // continue_orbit<LinearModel> with a model made from the same doubles: the same branch, point
  // for point and bit for bit, and its Neimark-Sacker point near the exact b = -2 (the
  // trapezoid's error at N = 100 is O(h^2): 1e-3 bounds it, the tolerance 1e-10).
  const auto family = std::make_shared<const LinearFamily>();
  const int N = 100;
  ContinuationOptions o;
  o.from = -1.5;
  o.to = -2.5;
  o.N = N;
  o.tolerance = 1e-10;
  const int b = family->index_of("b");
  const AnalysesAt along = analyses_along(family, family->base_values(), b, map_at(N));
  const ContinuationResult through_family = along(o.from)->continue_orbit(along, OrbitSettings{}, o);
  const ContinuationResult through_template = continue_orbit<LinearModel>(
      [](double p) { return LinearModel({-1, p, kTau, kTau}); }, Eigen::VectorXd::Zero(N), o);

  ASSERT_TRUE(through_family.failure.empty()) << through_family.failure;
  ASSERT_EQ(through_family.points.size(), through_template.points.size());
  for (size_t i = 0; i < through_family.points.size(); ++i)
    EXPECT_EQ(through_family.points[i].parameter, through_template.points[i].parameter) << i;
  ASSERT_EQ(through_family.bifurcations.size(), 1u);
  ASSERT_EQ(through_template.bifurcations.size(), 1u);
  EXPECT_EQ(through_family.bifurcations[0].type, BifurcationType::neimark_sacker);
  EXPECT_EQ(through_family.bifurcations[0].parameter, through_template.bifurcations[0].parameter);
  EXPECT_NEAR(through_family.bifurcations[0].parameter, -2.0, 1e-3);
}

namespace {

// The exact Neimark-Sacker curve in (a, b): lambda = i omega solves lambda = a + b exp(-lambda tau)
// where a = omega cot(omega tau), b = -omega / sin(omega tau), omega in (0, pi / tau); a falls
// from 1 / tau to -infinity along it, so b at a given a is one bisection away.
double exact_b(double a) {
  double lo = 1e-12, hi = std::numbers::pi / kTau - 1e-12;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (mid * std::cos(mid * kTau) / std::sin(mid * kTau) > a ? lo : hi) = mid;
  }
  const double omega = 0.5 * (lo + hi);
  return -omega / std::sin(omega * kTau);
}

}  // namespace

TEST(ProblemFamily, ABoundaryThroughTheFamilyCoversTheExactCurveWithItsBars) {
  // boundary_diagram through the public headers alone: the Neimark-Sacker curve of
  // x' = a x + b x(t - tau) for a in [-1, 0.5], searched in b from -0.6 down (the fold b = -a
  // stays above -0.5), at N = 50, 100, 200. Every point's extrapolation lies within its bars of
  // the exact curve (the bar in b and the slope times the bar in a), and the finest N's own point
  // within the trapezoid's O(h^2) of it. (The bars, about the finest N's own error, are some 3e4
  // times the extrapolation's error here: conservative, as boundary_point_study makes them.)
  const auto family = std::make_shared<const LinearFamily>();
  BoundaryDiagramOptions o;
  o.x = family->index_of("a");
  o.y = family->index_of("b");
  o.values = family->base_values();
  o.curve.x_from = -1;
  o.curve.x_to = 0.5;
  o.curve.y_from = -0.6;
  o.curve.y_to = -3;
  o.type = BifurcationType::neimark_sacker;
  o.Ns = {50, 100, 200};
  o.floquet.nev = 4;
  const BoundaryDiagram diagram = boundary_diagram(family, o);
  ASSERT_EQ(diagram.curves.size(), 1u);
  ASSERT_TRUE(diagram.failures.empty()) << diagram.failures;
  EXPECT_TRUE(diagram.stable_below);
  const BoundaryCurve& curve = diagram.curves[0];
  ASSERT_GE(curve.points.size(), 5u);
  EXPECT_EQ(curve.end, BoundaryEnd::to);
  double worst_ratio = 0, worst_finest = 0, worst_extrapolated = 0, worst_bar = 0;
  for (size_t k = 0; k < curve.points.size(); ++k) {
    const BoundaryPoint& p = curve.points[k];
    const BoundaryPointStudy& st = diagram.studies[0][k];
    // O(h^2): h = tau / 200, h^2 = 3.7e-5, the constant below 3 (measured: 1.1e-5 at worst)
    EXPECT_NEAR(p.y, exact_b(p.x), 1e-4) << "a = " << p.x;
    ASSERT_TRUE(std::isfinite(st.y_extrapolated)) << k;
    const double slope = (exact_b(st.x_extrapolated + 1e-6) - exact_b(st.x_extrapolated - 1e-6)) / 2e-6;
    const double bar = st.y_error_estimate + std::abs(slope) * st.x_error_estimate;
    const double error = std::abs(st.y_extrapolated - exact_b(st.x_extrapolated));
    EXPECT_LE(error, bar) << "a = " << st.x_extrapolated;
    worst_ratio = std::max(worst_ratio, error / bar);
    worst_finest = std::max(worst_finest, std::abs(p.y - exact_b(p.x)));
    worst_extrapolated = std::max(worst_extrapolated, error);
    worst_bar = std::max(worst_bar, bar);
  }
  // Richardson over three levels removes the h^2 term: measured 3.4e-10 against 1.1e-5
  EXPECT_LT(worst_extrapolated, 1e-3 * worst_finest);
  RecordProperty("worst_error_over_bar", format_number(worst_ratio));
  RecordProperty("worst_finest", format_number(worst_finest));
  RecordProperty("worst_extrapolated", format_number(worst_extrapolated));
  RecordProperty("worst_bar", format_number(worst_bar));
}

namespace {

// Mackey-Glass x' = beta x_tau / (1 + x_tau^n) - gamma x over tau (the map's period tau), the
// other parameters those of the scene mackey_glass_hopf.toml.
class MackeyGlassTauFamily final : public ProblemFamily {
 public:
  const std::vector<std::string>& parameter_names() const override { return names_; }
  const std::vector<double>& base_values() const override { return base_; }

 protected:
  FamilyMember make(const std::vector<double>& v) const override {
    try {
      return {builtin_analyses(MackeyGlassModel({0.2, 0.1, 10, v[0], v[0], 1.1})), ""};
    } catch (const BadInput& e) {
      return {nullptr, e.what()};
    }
  }

 private:
  std::vector<std::string> names_ = {"tau"};
  std::vector<double> base_ = {3};
};

}  // namespace

TEST(ProblemFamily, EquilibriaAlongAFamilyFindTheExactHopfPoint) {
  // continue_equilibrium on equilibria_along(a family), public headers only. At x* = 1 the
  // linearisation is lambda = -0.1 - 0.4 exp(-lambda tau): roots +-i omega with omega^2 = 0.4^2 -
  // 0.1^2 = 0.15 where cos(omega tau) = -1/4, the first at tau = arccos(-1/4) / sqrt(0.15). The
  // location is on the exact characteristic function (no discretisation error), to the
  // continuation's tolerance 1e-12 |to - from| = 3e-12, and the orbit branch born there
  // (orbits_from_hopf_points at N = 100, 200) leaves it with the period 2 pi / omega.
  const auto family = std::make_shared<const MackeyGlassTauFamily>();
  MapSettings map;
  map.N = 100;
  const AnalysesAt along = analyses_along(family, family->base_values(), 0, map);
  EquilibriumBranchOptions o;
  o.from = 3;
  o.to = 6;
  o.tolerance = 1e-12 * (o.to - o.from);
  const EquilibriumOptions eq;
  const EquilibriumBranch branch = continue_equilibrium(equilibria_along(along, eq), Eigen::VectorXd::Constant(1, 1.1), o);
  ASSERT_TRUE(branch.failure.empty()) << branch.failure;
  ASSERT_EQ(branch.bifurcations.size(), 1u);
  const EquilibriumBifurcation& hopf = branch.bifurcations[0];
  EXPECT_EQ(hopf.type, EquilibriumBifurcationType::hopf);
  const double exact = std::acos(-0.25) / std::sqrt(0.15);
  EXPECT_NEAR(hopf.parameter, exact, 1e-11);
  EXPECT_NEAR(hopf.omega, std::sqrt(0.15), 1e-10);

  ContinuationOptions orbit;
  orbit.from = hopf.parameter;
  orbit.to = 6;
  orbit.max_points = 8;
  const std::vector<HopfOrbitBranch> orbits = orbits_from_hopf_points(branch, along, {100, 200}, orbit);
  ASSERT_EQ(orbits.size(), 1u);
  ASSERT_EQ(orbits[0].levels.size(), 2u);
  EXPECT_EQ(orbits[0].hopf, &hopf);
  ASSERT_GE(orbits[0].finest().points.size(), 2u) << orbits[0].finest().failure;
  // the first point leaves the Hopf point with its period, to the discretisation's O(h^2)
  EXPECT_NEAR(orbits[0].finest().points.front().period, 2 * std::numbers::pi / std::sqrt(0.15), 1e-2);
}
