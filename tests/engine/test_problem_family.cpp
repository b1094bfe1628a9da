// ProblemFamily (problem_family.hpp) through the public headers alone, no scene: a family of the
// linear model x' = a x + b x(t - tau) written here as a C++ user writes one, its members, its
// refusals as outcomes, and a branch continued through it that is, bit for bit, the branch of the
// same model continued through the template with the same doubles.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "delayspec/builtin_analyses.hpp"
#include "delayspec/continuation.hpp"
#include "delayspec/errors.hpp"
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
