// `orbit = newton` through the CLI: the JSON orbit report, an unstable orbit that `simulate`
// cannot find (exit 3) but `newton` can, and the bad-input / numerical-failure exit codes of the
// Newton keys (orbit_tolerance, orbit_max_iterations, orbit_guess_periods).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_support.hpp"
#include "delayspec_test_paths.hpp"

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::run;

const std::string kScene = DELAYSPEC_SOURCE_DIR "/data/scenes/default.toml";

}  // namespace

TEST(OrbitNewtonCli, JsonReportsNewtonAndMatchesSimulation) {
  CliResult newton = run({"floquet", kScene, "--json", "--set", "N=60", "--set", "orbit=newton", "--set",
                          "orbit_guess_periods=2", "--set", "nev=3"});
  ASSERT_EQ(newton.status, 0) << newton.err;
  auto j = nlohmann::json::parse(newton.out);
  ASSERT_TRUE(j.contains("orbit"));
  EXPECT_EQ(j["orbit"]["method"], "newton");
  EXPECT_EQ(j["orbit"]["periods"], 2);
  EXPECT_GE(j["orbit"]["newton_iterations"].get<int>(), 1);
  EXPECT_EQ(j["orbit"]["newton_residuals"].size(), j["orbit"]["newton_iterations"].get<size_t>() + 1);
  EXPECT_LT(j["orbit"]["residual"].get<double>(), 1e-12);  // rounding of K = 60 steps
  EXPECT_EQ(j["orbit"]["contacts"], 1);                    // the paper's orbit touches the obstacle once per period

  CliResult simulated =
      run({"floquet", kScene, "--json", "--set", "N=60", "--set", "nev=3", "--set", "orbit=simulate"});
  ASSERT_EQ(simulated.status, 0) << simulated.err;
  auto s = nlohmann::json::parse(simulated.out);
  EXPECT_EQ(s["orbit"]["method"], "simulate");
  // Same orbit (to ~1e-12, the simulation's settling tolerance / (1 - |mu_1|)), so the same
  // multipliers up to that perturbation times their condition: 1e-9 is generous.
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(j["multipliers"][i]["abs"].get<double>(), s["multipliers"][i]["abs"].get<double>(), 1e-9);
}

TEST(OrbitNewtonCli, UnstableOrbitNewtonSucceedsWhereSimulationFails) {
  // tau = T, negative gain: the period-1 orbit is unstable (see test_orbit_newton.cpp).
  std::vector<std::string> common = {"floquet", kScene,      "--set", "N=40",  "--set",
                                     "k=-0.1",  "--set",     "nev=2", "--set", "orbit_max_periods=400",
                                     "--set",   "events=off"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = common;
    args.insert(args.end(), extra.begin(), extra.end());
    return run(args);
  };
  CliResult simulated = with({"--set", "orbit=simulate"});
  EXPECT_EQ(simulated.status, 3) << simulated.err;
  CliResult newton = with({"--json", "--set", "orbit=newton", "--set", "orbit_guess_periods=0"});
  ASSERT_EQ(newton.status, 0) << newton.err;
  auto j = nlohmann::json::parse(newton.out);
  EXPECT_GT(j["multipliers"][0]["abs"].get<double>(), 1.5);  // about 1.9: clearly unstable
}

TEST(OrbitNewtonCli, NewtonFailureIsExitThree) {
  // From the rest state the guess is O(1) off the orbit; one iteration cannot converge:
  // exit 3 naming iterations and residual.
  CliResult r = run({"floquet", kScene, "--set", "N=40", "--set", "x0=0", "--set", "v0=0", "--set", "orbit=newton",
                     "--set", "orbit_max_iterations=1", "--set", "orbit_guess_periods=0"});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("orbit by Newton"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("iterations"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST(OrbitNewtonCli, BadNewtonKeysAreExitTwo) {
  for (auto [key, value] : std::vector<std::pair<std::string, std::string>>{{"orbit_max_iterations", "0"},
                                                                            {"orbit_max_iterations", "x"},
                                                                            {"orbit_max_iterations", "1.5"},
                                                                            {"orbit_guess_periods", "-1"},
                                                                            {"orbit_guess_periods", "many"},
                                                                            {"orbit_tolerance", "0"},
                                                                            {"orbit_tolerance", "nan"},
                                                                            {"orbit_tolerance", "-2"}}) {
    CliResult r =
        run({"floquet", "--set", "orbit=newton", "--set", "N=8", "--set", "solver=dense", "--set", key + "=" + value});
    EXPECT_EQ(r.status, 2) << key << "=" << value << ": " << r.err;
    EXPECT_NE(r.err.find("`" + key), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(value), std::string::npos) << r.err;
  }
}
