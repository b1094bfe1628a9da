// The `delayspec floquet` command: exit codes, JSON keys, and one test per bad-input path
// (CLI contract: exit 2 and a message naming the key and the value).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_support.hpp"
#include "equation_scenes.hpp"
#include "delayspec/errors.hpp"
#include "delayspec_test_paths.hpp"

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::run;

struct FloquetBadValue {
  const char* model;
  const char* key;
  const char* value;
};

void PrintTo(const FloquetBadValue& b, std::ostream* os) { *os << b.model << ":" << b.key << "=" << b.value; }

class FloquetBadInput : public ::testing::TestWithParam<FloquetBadValue> {};

}  // namespace

TEST_P(FloquetBadInput, ExitsTwoNamingKeyAndValue) {
  const FloquetBadValue b = GetParam();
  CliResult r = run({"floquet", "--set", std::string("model=") + b.model, "--set", "solver=dense", "--set", "N=8",
                     "--set", std::string(b.key) + "=" + b.value});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(std::string("`") + b.key), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(b.value), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << "no partial result on stdout: " << r.out;
}

// clang-format off
INSTANTIATE_TEST_SUITE_P(Keys, FloquetBadInput, ::testing::Values(
    FloquetBadValue{"impact", "zeta", "abc"}, FloquetBadValue{"impact", "zeta", "nan"}, FloquetBadValue{"impact", "zeta", "-1"},
    FloquetBadValue{"impact", "e", "x"}, FloquetBadValue{"impact", "e", "inf"},
    FloquetBadValue{"impact", "a", ""}, FloquetBadValue{"impact", "a", "1e999"},
    FloquetBadValue{"impact", "beta", "-3"}, FloquetBadValue{"impact", "beta", "NaN"},
    FloquetBadValue{"impact", "omega", "0"}, FloquetBadValue{"impact", "omega", "-0.8"}, FloquetBadValue{"impact", "omega", "fast"},
    FloquetBadValue{"impact", "k", "one"}, FloquetBadValue{"impact", "k", "-inf"},
    FloquetBadValue{"impact", "tau_over_T", "0"}, FloquetBadValue{"impact", "tau_over_T", "-1"},
    FloquetBadValue{"impact", "tau", "-2"}, FloquetBadValue{"impact", "tau", "nan"},
    FloquetBadValue{"impact", "x0", "1,2"}, FloquetBadValue{"impact", "v0", "inf"},
    FloquetBadValue{"impact", "orbit_period", "0"}, FloquetBadValue{"impact", "orbit_period", "1.5"},
    FloquetBadValue{"impact", "N", "0"}, FloquetBadValue{"impact", "N", "-5"}, FloquetBadValue{"impact", "N", "ten"},
    FloquetBadValue{"impact", "N", "3.5"}, FloquetBadValue{"impact", "N", ""}, FloquetBadValue{"impact", "N", "99999999999999999999"},
    FloquetBadValue{"impact", "events", "maybe"}, FloquetBadValue{"impact", "jacobian", "exact"},
    FloquetBadValue{"impact", "nev", "0"}, FloquetBadValue{"impact", "nev", "100000"}, FloquetBadValue{"impact", "nev", "many"},
    FloquetBadValue{"impact", "solver", "magic"}, FloquetBadValue{"impact", "orbit", "guess"},
    FloquetBadValue{"impact", "model", "duffing"},
    FloquetBadValue{"linear", "a", "nan"}, FloquetBadValue{"linear", "b", "b"}, FloquetBadValue{"linear", "tau", "0"},
    FloquetBadValue{"linear", "tau", "-1"}, FloquetBadValue{"linear", "period", "0"}, FloquetBadValue{"linear", "period", "inf"},
    FloquetBadValue{"mathieu", "kappa", "nan"}, FloquetBadValue{"mathieu", "delta", "x"}, FloquetBadValue{"mathieu", "eps", "inf"},
    FloquetBadValue{"mathieu", "b", "--"}));
// clang-format on

TEST(FloquetCli, UnknownKeyIsBadInput) {
  CliResult r = run({"floquet", "--set", "model=linear", "--set", "kappa=1", "--set", "solver=dense"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("`kappa` (= 1, from --set) is not read by floquet with model = linear"), std::string::npos)
      << r.err;
}

TEST(FloquetCli, UnknownCommandAndMalformedSet) {
  EXPECT_EQ(run({"flocket"}).status, 2);
  CliResult r = run({"floquet", "--set", "N"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("KEY=VALUE"), std::string::npos) << r.err;
}

TEST(FloquetCli, MissingOrBrokenSceneFile) {
  CliResult r = run({"floquet", "/nonexistent/scene.toml"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("/nonexistent/scene.toml"), std::string::npos) << r.err;
}

TEST(FloquetCli, IncompatibleNForRationalDelay) {
  // tau = 2T needs N even: 5 steps per delay would be 2.5 steps per period.
  CliResult r = run({"floquet", "--set", "model=linear", "--set", "tau=1", "--set", "period=0.5", "--set", "N=5",
                     "--set", "solver=dense"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("`N = 5`"), std::string::npos) << r.err;
}

TEST(FloquetCli, JsonHasContractKeysAndSortedMultipliers) {
  CliResult r = run({"floquet", "--json", "--set", "model=linear", "--set", "a=-1", "--set", "b=-2", "--set", "N=40",
                     "--set", "solver=dense", "--set", "nev=5"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);  // exactly one JSON object on stdout
  for (const char* key : {"model", "N", "dimension", "solver", "multipliers", "seconds", "operator_applications"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["dimension"], 41);
  EXPECT_EQ(j["multipliers"].size(), 5u);
  for (size_t i = 0; i + 1 < j["multipliers"].size(); ++i)
    EXPECT_GE(j["multipliers"][i]["abs"].get<double>(), j["multipliers"][i + 1]["abs"].get<double>());
}

TEST(FloquetCli, FractionalDelayRuns) {
  // issue 2: tau = 3.8 with omega = 0.8 (not a rational multiple of T) must run.
  CliResult r = run({"floquet", "--json", "--set", "tau=3.8", "--set", "omega=0.8", "--set", "k=0.12", "--set", "N=40",
                     "--set", "solver=dense", "--set", "events=off", "--set", "a=0.2"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["dimension"].get<int>(), 80);
}

TEST(FloquetCli, DefaultSceneRuns) {
  CliResult r = run({"floquet", DELAYSPEC_SOURCE_DIR "/data/scenes/default.toml", "--set", "N=60", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_LT(j["multipliers"][0]["abs"].get<double>(), 1.0);  // the period-1 orbit is stable
}

// Issue 61 item 8: orbit_series = on gives the orbit over one map as a time series, by the
// model's state names. Checked against what does not come from the orbit search: a long
// simulation of the same discrete map (the stable orbit's Poincare point after 100 periods), the
// grid's step (t), v = dx/dt (central differences, O(h^2)), and for the Pyragas orbit of unknown
// period its closed form, a circle (the equation is rotation invariant, so the discrete orbit is
// one too; its radius^2 -> -lam = 0.005 as N grows, within 5% at N = 40).
TEST(FloquetCli, OrbitSeriesIsTheOrbitOverOneMapByStateName) {
  const std::filesystem::path dir = delayspec::testing::fresh_dir("floquet_orbit_series");
  std::filesystem::create_directories(dir);
  const std::string scene = (dir / "forced_pair.toml").string();
  std::ofstream(scene) << delayspec::testing::kForcedPairEquationsScene;
  const std::string cache = std::string("model_cache=") + DELAYSPEC_TEST_MODEL_CACHE;
  const CliResult f = run({"floquet", scene, "--json", "--set", cache, "--set", "N=40", "--set", "orbit_series=on",
                           "--set", "error_bars=off"});
  ASSERT_EQ(f.status, 0) << f.err;
  const auto j = nlohmann::json::parse(f.out);
  const auto& s = j["orbit_series"];
  const size_t K = j["steps_per_map"].get<size_t>();
  const double h = j["h"].get<double>();
  ASSERT_EQ(s["t"].size(), K);
  ASSERT_EQ(s["x"].size(), K);
  ASSERT_EQ(s["v"].size(), K);
  for (size_t l = 0; l < K; ++l) EXPECT_NEAR(s["t"][l].get<double>(), l * h, 1e-12);
  for (size_t l = 1; l + 1 < K; ++l)
    EXPECT_NEAR((s["x"][l + 1].get<double>() - s["x"][l - 1].get<double>()) / (2 * h), s["v"][l].get<double>(), 1e-3)
        << l;
  const CliResult sim = run({"simulate", scene, "--json", "--set", cache, "--set", "N=40", "--set",
                             "t_end=" + delayspec::format_number(200 * std::acos(-1.0))});
  ASSERT_EQ(sim.status, 0) << sim.err;
  const auto last = nlohmann::json::parse(sim.out)["poincare"].back();
  EXPECT_NEAR(last[1].get<double>(), s["x"][0].get<double>(), 1e-10);
  EXPECT_NEAR(last[2].get<double>(), s["v"][0].get<double>(), 1e-10);
  // the text prints it too; without the key, neither does
  const CliResult text =
      run({"floquet", scene, "--set", cache, "--set", "N=40", "--set", "orbit_series=on", "--set", "error_bars=off"});
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("orbit series (" + std::to_string(K) + " samples over one map):\n"), std::string::npos)
      << text.out;
  const CliResult plain = run({"floquet", scene, "--json", "--set", cache, "--set", "N=40", "--set", "error_bars=off"});
  EXPECT_FALSE(nlohmann::json::parse(plain.out).contains("orbit_series"));
  const CliResult bad = run({"floquet", scene, "--set", cache, "--set", "orbit_series=yes"});
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("`orbit_series = yes`"), std::string::npos) << bad.err;

  const CliResult pyragas =
      run({"floquet", std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/pyragas_oscillator.toml", "--json", "--set",
           cache, "--set", "N=40", "--set", "orbit_series=on", "--set", "error_bars=off"});
  ASSERT_EQ(pyragas.status, 0) << pyragas.err;
  const auto p = nlohmann::json::parse(pyragas.out);
  const auto& o = p["orbit_series"];
  const size_t n = o["t"].size();
  ASSERT_GT(n, 10u);
  EXPECT_NEAR(o["t"][n - 1].get<double>(), (n - 1.0) / n * p["period"].get<double>(), 1e-12);
  for (size_t l = 0; l < n; ++l) {
    const double r2 = std::pow(o["x"][l].get<double>(), 2) + std::pow(o["y"][l].get<double>(), 2);
    EXPECT_NEAR(r2, 0.005, 2.5e-4) << l;
  }
  std::filesystem::remove_all(dir);
}
