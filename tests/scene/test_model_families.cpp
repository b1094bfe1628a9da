// The scene's problem families (builtin_family.hpp, equation_model.hpp): every parameter a family
// sets as a double is the model the scene's keys give with that value as text, bit for bit. The
// keys carry rules the setters must keep (linear's and mackey-glass's period follows tau unless
// given; the impact model's tau or tau_over_T; an equation model's tau_over_T); an independent
// path through the text is the check. "The same model" is checked by what it computes: the
// delays, the period, the switches, and the states of a few periods simulated from its history.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "delayspec/errors.hpp"
#include "scene/keys/config.hpp"
#include "scene/problem/problem.hpp"
#include "equation_scenes.hpp"

using delayspec::BadInput;
using delayspec::format_number;
using delayspec::cli::Config;
using delayspec::cli::Problem;

namespace {

Config scene(const std::string& text, const std::vector<std::pair<std::string, std::string>>& sets) {
  Config config = Config::from_scene_text(text, "test.toml");
  if (config.has("equations")) config.set("model_cache", DELAYSPEC_TEST_MODEL_CACHE, "test");
  for (const auto& [key, value] : sets) config.set(key, value, "test");
  return config;
}

// What a model computes, or why it refuses: enough to tell two models apart.
std::string fingerprint(const Problem& p) {
  // (appends: GCC 12 warns falsely on "literal" + string, -Wrestrict)
  std::string text;
  const auto add = [&text](const char* label, double x) {
    text.append(label).append(format_number(x));  // the shortest exact spelling: bit for bit
  };
  add("tau ", p.analyses->tau());
  add(" period ", p.analyses->period());
  for (double d : p.analyses->delays()) add(" delay ", d);
  for (double s : p.analyses->time_switches()) add(" switch ", s);
  try {
    for (const Eigen::VectorXd& u : p.analyses->section_sequence(p.map_settings(), 0, 3))
      for (double x : u) add(" ", x);
  } catch (const std::exception& e) {
    text.append(" failed: ").append(e.what());
  }
  return text;
}

// Each parameter of the family of `text` + `sets`, set to a new value through the family and
// through the keys: the same model, or the same refusal (a grid that no longer fits N).
void expect_setters_are_the_keys(const std::string& text, const std::vector<std::pair<std::string, std::string>>& sets) {
  const int N = 60;
  Config base_config = scene(text, sets);
  const Problem base = delayspec::cli::read_problem(base_config, N);
  ASSERT_FALSE(base.family->parameter_names().empty());
  for (const std::string& name : base.family->parameter_names()) {
    const int i = base.family->index_of(name);
    const double old = base.parameter_values[static_cast<size_t>(i)];
    // half as much again (a NaN or 0 base means "follows another key": a value of its own)
    const double value = std::isnan(old) || old == 0 ? 1.5 : old * 1.5;
    std::string rejected;
    const std::optional<Problem> by_family =
        delayspec::cli::problem_at(base, delayspec::ProblemFamily::with(base.parameter_values, i, value), N, rejected);
    const std::string family_outcome = by_family ? fingerprint(*by_family) : "refused: " + rejected;
    Config keyed = scene(text, sets);
    keyed.set(name, format_number(value), "test");
    std::string keys_outcome;
    try {
      keys_outcome = fingerprint(delayspec::cli::read_problem(keyed, N));
    } catch (const BadInput& e) {
      keys_outcome = std::string("refused: ") + e.what();
    }
    EXPECT_EQ(family_outcome, keys_outcome) << base.model_name << ": " << name << " = " << value;
    if (by_family) {
      EXPECT_NE(family_outcome, fingerprint(base)) << base.model_name << ": " << name << " changes nothing";
    }
  }
}

}  // namespace

TEST(ModelFamilies, EverySetterIsItsKey) {
  expect_setters_are_the_keys("model = \"impact\"\nk = 0.2\n", {});                  // tau_over_T, tau
  expect_setters_are_the_keys("model = \"impact\"\nk = 0.2\ntau = 7\n", {});         // tau given
  expect_setters_are_the_keys("model = \"linear\"\n", {});                           // period follows tau
  expect_setters_are_the_keys("model = \"linear\"\nperiod = 1.5\n", {});             // period given
  expect_setters_are_the_keys("model = \"mathieu\"\n", {});
  expect_setters_are_the_keys("model = \"mackey-glass\"\ntau = 6\nx0 = 1.1\n", {});  // period follows tau
  expect_setters_are_the_keys("model = \"milling\"\nradial_immersion = 0.3\ndepth = 2e-4\n", {});
  expect_setters_are_the_keys("model = \"milling\"\nradial_immersion = 0.3\ndepth = 2e-4\npitch_angles = [80, 100, 80, 100]\n",
                              {});
  using delayspec::testing::kMackeyGlassEquationsScene;
  expect_setters_are_the_keys(kMackeyGlassEquationsScene, {});                       // the delay from the table
  expect_setters_are_the_keys(kMackeyGlassEquationsScene, {{"tau_over_T", "0.5"}});  // the delay in periods
}

TEST(ModelFamilies, NotAParameterIsNamedWithTheModelsParameters) {
  Config config = scene("model = \"linear\"\n", {});
  const Problem p = delayspec::cli::read_problem(config, 20);
  for (const char* key : {"N", "model", "events", "x0", "continue_from"}) {
    try {
      delayspec::cli::family_parameter(p, "continue_key", key);
      ADD_FAILURE() << key << " taken as a parameter";
    } catch (const BadInput& e) {
      EXPECT_EQ(std::string(e.what()), "`continue_key = " + std::string(key) +
                                           "`: not a model parameter of model linear (its parameters: a, b, tau, period)");
    }
  }
}
