// Problem, the one hand-off from the configuration to the computation: its grid and dimensions
// are functions of (model, N, orbit_period) and agree with the engine's map of the model; events and
// jacobian are enums whose text appears only at the edge, with no silent fallback.
#include <gtest/gtest.h>

#include <string>
#include <tuple>
#include <type_traits>
#include <variant>

#include "delayspec/errors.hpp"
#include "delayspec/stepper.hpp"
#include "delayspec/stroboscopic_map.hpp"
#include "scene/problem/problem.hpp"

using delayspec::BadInput;
using delayspec::EventMode;
using delayspec::JacobianMode;
using delayspec::cli::Config;
using delayspec::cli::Problem;

namespace {

Problem problem_of(const std::string& model, int N, int orbit_period = 1) {
  Config config;
  config.set("model", model, "test");
  config.set("N", std::to_string(N), "test");
  if (orbit_period != 1) config.set("orbit_period", std::to_string(orbit_period), "test");
  return delayspec::cli::read_problem(config);
}

}  // namespace

TEST(Problem, DimensionsAgreeWithTheEnginesMap) {
  // d (M + 1) by hand: linear and mackey-glass d = 1, tau = T, M = N; impact and mathieu d = 2.
  EXPECT_EQ(problem_of("linear", 20).dimension(), 21);
  EXPECT_EQ(problem_of("mackey-glass", 30).dimension(), 31);
  EXPECT_EQ(problem_of("mathieu", 40).dimension(), 82);
  for (const std::string model : {"impact", "linear", "mathieu", "mackey-glass"}) {
    for (int N : {16, 50}) {
      const Problem p = problem_of(model, N, model == "impact" || model == "mathieu" ? 2 : 1);
      // The engine's own map of the model, built here as the analyses build theirs.
      const auto [n, K, d] = std::visit(
          [&](const auto& model_) {
            using Model = std::decay_t<decltype(model_)>;
            const delayspec::StroboscopicMap<Model> map(
                delayspec::TrapezoidStepper<Model>(model_, delayspec::cli::step_options(p)), p.grid());
            return std::tuple<long, int, int>(map.dimension(), map.grid().K, Model::d);
          },
          *p.model);
      EXPECT_EQ(p.dimension(), n) << model << " N = " << N;
      EXPECT_EQ(p.grid().K, K) << model << " N = " << N;
      EXPECT_EQ(p.state_dimension(), d) << model;
    }
  }
  // orbit_period p: one map is p periods, the history (M) does not change
  const Problem one = problem_of("mathieu", 40), two = problem_of("mathieu", 40, 2);
  EXPECT_EQ(two.grid().K, 2 * one.grid().K);
  EXPECT_EQ(two.dimension(), one.dimension());
  // the grid follows N: no second copy of it to go stale
  Problem p = one;
  p.N = 80;
  EXPECT_EQ(p.dimension(), 162);
}

TEST(Problem, EventAndJacobianModesAreEnumsWithTextAtTheEdge) {
  Config config;
  config.set("model", "impact", "test");
  config.set("events", "linear", "test");
  config.set("jacobian", "frozen", "test");
  const Problem p = delayspec::cli::read_problem(config);
  EXPECT_EQ(p.events, EventMode::linear);
  EXPECT_EQ(p.jacobian, JacobianMode::frozen);
  EXPECT_EQ(delayspec::cli::step_options(p).events, EventMode::linear);
  EXPECT_EQ(delayspec::cli::step_options(p).jacobian, JacobianMode::frozen);
  for (EventMode mode : {EventMode::on, EventMode::linear, EventMode::off})
    EXPECT_EQ(delayspec::cli::parse_event_mode(delayspec::cli::to_string(mode)), mode);
  // No silent fallback: an unknown text is BadInput naming the key it came from.
  try {
    delayspec::cli::parse_event_mode("maybe", "events_before_control");
    ADD_FAILURE() << "`maybe` accepted";
  } catch (const BadInput& e) {
    EXPECT_EQ(std::string(e.what()), "`events_before_control = maybe`: must be one of on, linear, off");
  }
  Config bad;
  bad.set("events", "sometimes", "test");
  EXPECT_THROW(delayspec::cli::read_problem(bad), BadInput);
}
