// The matrix-free monodromy against its own dense assembly and against finite differences of
// the discrete map it linearises.
#include <gtest/gtest.h>

#include <random>

#include "delayspec/contact_aligned_orbit.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/model_grid.hpp"
#include "delayspec/model_impact.hpp"
#include "delayspec/model_linear.hpp"
#include "delayspec/model_mathieu.hpp"
#include "delayspec/model_milling.hpp"
#include "delayspec/monodromy.hpp"
#include "delayspec/orbit_search.hpp"
#include "delayspec/orbit_simulation.hpp"
#include "delayspec/stroboscopic_map.hpp"
#include "test_support.hpp"

using namespace delayspec;
using delayspec::testing::random_matrix;

namespace {

// apply / apply_block against to_dense() times the same vectors. Both compute the same sums
// of K products in a different order; for a contracting or mildly expanding product the
// rounding differences are a few hundred ulps of the result: 1e-13 relative.
template <int D>
void expect_apply_matches_dense(const Monodromy<D>& op) {
  const Eigen::MatrixXd dense = op.to_dense();
  const Eigen::MatrixXd X = random_matrix(op.rows(), 7, 42);
  Eigen::MatrixXd Y;
  op.apply_block(X, Y);
  const Eigen::MatrixXd reference = dense * X;
  EXPECT_LE((Y - reference).norm(), 1e-13 * reference.norm());
  for (long j = 0; j < X.cols(); ++j) {
    Eigen::VectorXd y;
    op.apply(X.col(j), y);
    EXPECT_LE((y - reference.col(j)).norm(), 1e-13 * reference.col(j).norm());
  }
}

template <class Model>
Monodromy<Model::d> linear_monodromy(const Model& model, int N) {
  HistoryGrid grid = make_grid(model.tau(), model.period(), N);
  StroboscopicMap<Model> map(TrapezoidStepper<Model>(model), grid);
  return map.monodromy(Eigen::VectorXd::Zero(map.dimension()));
}

}  // namespace

TEST(Monodromy, ApplyMatchesDenseAlignedDelay) {
  expect_apply_matches_dense(linear_monodromy(LinearModel({.a = -1, .b = 0.5, .tau = 1, .period = 1}), 37));
  expect_apply_matches_dense(linear_monodromy(LinearModel({.a = -1, .b = 0.5, .tau = 1, .period = 0.5}), 38));
  expect_apply_matches_dense(linear_monodromy(LinearModel({.a = 0.3, .b = -1.5, .tau = 1, .period = 2}), 38));
  expect_apply_matches_dense(linear_monodromy(MathieuModel(), 30));
}

TEST(Monodromy, ApplyMatchesDenseFractionalDelay) {
  auto op = linear_monodromy(LinearModel({.a = -0.5, .b = 0.7, .tau = 1, .period = 1.37}), 29);
  ASSERT_FALSE(op.grid().aligned());
  expect_apply_matches_dense(op);
}

TEST(Monodromy, ApplyMatchesDenseOnImpactOrbit) {
  ImpactModel model;
  HistoryGrid grid = make_grid(model.tau(), model.period(), 60);
  StroboscopicMap<ImpactModel> map(TrapezoidStepper<ImpactModel>(model), grid);
  Eigen::VectorXd U = map.constant_history(model.initial_state());
  for (int i = 0; i < 50; ++i) U = map.apply(U);  // a state with nontrivial step maps
  expect_apply_matches_dense(map.monodromy(U));
}

TEST(Monodromy, BlockWiderThanOnePassMatchesDense) {
  auto op = linear_monodromy(LinearModel({.a = -0.5, .b = 0.7, .tau = 1, .period = 1.37}), 40);
  const Eigen::MatrixXd X = random_matrix(op.rows(), 150, 7);  // > 64: several passes
  Eigen::MatrixXd Y;
  op.apply_block(X, Y);
  const Eigen::MatrixXd reference = op.to_dense() * X;
  EXPECT_LE((Y - reference).norm(), 1e-13 * reference.norm());
}

TEST(Monodromy, RejectsWrongSizes) {
  auto op = linear_monodromy(LinearModel(), 10);
  Eigen::VectorXd y;
  try {
    op.apply(Eigen::VectorXd::Zero(5), y);
    FAIL() << "no exception";
  } catch (const BadInput& e) {
    EXPECT_NE(std::string(e.what()).find("5"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("11"), std::string::npos);
  }
  Eigen::MatrixXd Y;
  EXPECT_THROW(op.apply_block(Eigen::MatrixXd::Zero(3, 2), Y), BadInput);
  EXPECT_THROW(Monodromy<1>(op.grid(), {}), BadInput);
}

// Central differences of one step: for a model affine in (y, y_tau) inside one region the
// difference quotient is exact up to rounding, which with step delta = 1e-6 on O(1) states
// is ~ eps / delta = 2e-10 relative; 1e-7 leaves room for O(1) scale factors while still
// catching any wrong term (those are O(h) = 1e-2 or larger).
template <class Model>
void expect_step_map_matches_finite_differences(const Model& model, double t, double h, const Vec<Model::d>& u0,
                                                const Vec<Model::d>& w0, const Vec<Model::d>& w1) {
  constexpr int D = Model::d;
  TrapezoidStepper<Model> stepper(model, {.events = EventMode::off});
  StepMap<D> map;
  stepper.step(t, h, u0, w0, w1, map);
  const double delta = 1e-6;
  Mat<D> P, Q, R;
  StepMap<D> scratch;
  for (int c = 0; c < D; ++c) {
    Vec<D> e = Vec<D>::Zero();
    e[c] = delta;
    P.col(c) =
        (stepper.step(t, h, u0 + e, w0, w1, scratch) - stepper.step(t, h, u0 - e, w0, w1, scratch)) / (2 * delta);
    Q.col(c) =
        (stepper.step(t, h, u0, w0 + e, w1, scratch) - stepper.step(t, h, u0, w0 - e, w1, scratch)) / (2 * delta);
    R.col(c) =
        (stepper.step(t, h, u0, w0, w1 + e, scratch) - stepper.step(t, h, u0, w0, w1 - e, scratch)) / (2 * delta);
  }
  const double scale = 1 + map.P.norm() + map.Q.norm() + map.R.norm();
  EXPECT_LE((P - map.P).norm(), 1e-7 * scale) << "P\n" << P << "\nvs\n" << map.P;
  EXPECT_LE((Q - map.Q).norm(), 1e-7 * scale) << "Q\n" << Q << "\nvs\n" << map.Q;
  EXPECT_LE((R - map.R).norm(), 1e-7 * scale) << "R\n" << R << "\nvs\n" << map.R;
}

TEST(StepMap, MatchesFiniteDifferencesLinear) {
  expect_step_map_matches_finite_differences(LinearModel({.a = -1.3, .b = 0.7}), 0.0, 0.05, Vec<1>(0.4), Vec<1>(-0.2),
                                             Vec<1>(0.9));
}

TEST(StepMap, MatchesFiniteDifferencesMathieu) {
  expect_step_map_matches_finite_differences(MathieuModel(), 1.1, 0.1, Vec<2>(0.3, -0.8), Vec<2>(0.5, 0.1),
                                             Vec<2>(-0.4, 0.6));
}

TEST(StepMap, MatchesFiniteDifferencesImpactBothRegions) {
  ImpactModel model({.k = 0.8});
  // free flight (x < e) and contact (x > e) with both nodes on the same side
  expect_step_map_matches_finite_differences(model, 0.7, 0.02, Vec<2>(0.5, 0.3), Vec<2>(0.2, 0.1), Vec<2>(0.25, 0.0));
  expect_step_map_matches_finite_differences(model, 0.7, 0.02, Vec<2>(1.3, 0.3), Vec<2>(0.2, 0.1), Vec<2>(0.25, 0.0));
}

// Central differences of the whole stroboscopic map of a linear model against the monodromy
// columns: the map is linear, so the difference quotient is exact up to rounding of the
// K-step products (~1e-16 |P(U)| / delta = 1e-10 relative with delta = 1e-6).
TEST(Monodromy, MatchesFiniteDifferencesOfStroboscopicMap) {
  MathieuModel model({.kappa = 0.1, .delta = 1, .eps = 1, .b = 0.2});
  HistoryGrid grid = make_grid(model.tau(), model.period(), 20);
  StroboscopicMap<MathieuModel> map(TrapezoidStepper<MathieuModel>(model), grid);
  Eigen::VectorXd U = random_matrix(map.dimension(), 1, 3).col(0);
  Eigen::MatrixXd dense = map.monodromy(U).to_dense();
  const double delta = 1e-6;
  for (long c = 0; c < map.dimension(); c += 5) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(map.dimension());
    e[c] = delta;
    Eigen::VectorXd fd = (map.apply(U + e) - map.apply(U - e)) / (2 * delta);
    EXPECT_LE((fd - dense.col(c)).norm(), 1e-7 * (1 + dense.col(c).norm())) << "column " << c;
  }
}

// On a grid aligned with the switches (grid.hpp; issue 58): the monodromy applied matrix-free
// equals its dense assembly (1e-13, as above), and its columns equal central differences of the
// stroboscopic map. Milling at a/D = 0.05 is linear: the difference quotient is exact up to
// rounding (1e-7 as above). The impact orbit on the grid aligned with its contact
// (contact_aligned_orbit.hpp): every step in a fixed region, so the map is smooth in U near the
// orbit and its difference quotient meets the step maps to O(delta^2) and rounding: 1e-6 with
// delta = 1e-6 (|d2P| ~ beta = 28 within a contact's steps).
TEST(Monodromy, OnAlignedGridsMatchesDenseAndFiniteDifferences) {
  auto check = [](const auto& map, const Eigen::VectorXd& U, double tolerance) {
    const auto op = map.monodromy(U);
    ASSERT_TRUE(op.grid().has_breakpoints());
    expect_apply_matches_dense(op);
    const Eigen::MatrixXd dense = op.to_dense();
    const double delta = 1e-6;
    for (long c = 0; c < map.dimension(); c += 7) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(map.dimension());
      e[c] = delta;
      const Eigen::VectorXd fd = (map.apply(U + e) - map.apply(U - e)) / (2 * delta);
      EXPECT_LE((fd - dense.col(c)).norm(), tolerance * (1 + dense.col(c).norm())) << "column " << c;
    }
  };
  MillingParameters q;
  q.radial_immersion = 0.05;
  q.depth = 2e-3;
  const MillingModel milling(q);
  const StroboscopicMap<MillingModel> milling_map(TrapezoidStepper<MillingModel>(milling),
                                                  model_grid(milling, 60, 1, GridLayout::aligned));
  check(milling_map, random_matrix(milling_map.dimension(), 1, 5).col(0), 1e-7);

  ImpactParameters p;
  p.k = 0.2, p.x0 = -0.0566, p.v0 = 1.0101;
  const ImpactModel impact(p);
  const StroboscopicMap<ImpactModel> uniform(TrapezoidStepper<ImpactModel>(impact),
                                             make_grid(impact.tau(), impact.period(), 400));
  const PeriodicOrbit orbit = find_orbit(impact, uniform, OrbitSettings{});
  std::vector<Vec<2>> states;
  uniform.apply(orbit.history, nullptr, &states);
  std::string why;
  const auto aligned = contact_aligned_orbit(uniform, states, ContactAlignmentOptions{}, why);
  ASSERT_TRUE(aligned) << why;
  const StroboscopicMap<ImpactModel> on_contacts(uniform.stepper(), aligned->grid);
  check(on_contacts, aligned->orbit.history, 1e-6);
}
