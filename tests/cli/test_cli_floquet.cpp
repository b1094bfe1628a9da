// The `delayspec floquet` command: exit codes, JSON keys, and one test per bad-input path
// (CLI contract: exit 2 and a message naming the key and the value).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_support.hpp"
#include "delayspec_test_paths.hpp"

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::run;

struct BadValue {
  const char* model;
  const char* key;
  const char* value;
};

void PrintTo(const BadValue& b, std::ostream* os) { *os << b.model << ":" << b.key << "=" << b.value; }

class FloquetBadInput : public ::testing::TestWithParam<BadValue> {};

}  // namespace

TEST_P(FloquetBadInput, ExitsTwoNamingKeyAndValue) {
  const BadValue b = GetParam();
  CliResult r = run({"floquet", "--set", std::string("model=") + b.model, "--set", "solver=dense", "--set", "N=8",
                     "--set", std::string(b.key) + "=" + b.value});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(std::string("`") + b.key), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(b.value), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << "no partial result on stdout: " << r.out;
}

// clang-format off
INSTANTIATE_TEST_SUITE_P(Keys, FloquetBadInput, ::testing::Values(
    BadValue{"impact", "zeta", "abc"}, BadValue{"impact", "zeta", "nan"}, BadValue{"impact", "zeta", "-1"},
    BadValue{"impact", "e", "x"}, BadValue{"impact", "e", "inf"},
    BadValue{"impact", "a", ""}, BadValue{"impact", "a", "1e999"},
    BadValue{"impact", "beta", "-3"}, BadValue{"impact", "beta", "NaN"},
    BadValue{"impact", "omega", "0"}, BadValue{"impact", "omega", "-0.8"}, BadValue{"impact", "omega", "fast"},
    BadValue{"impact", "k", "one"}, BadValue{"impact", "k", "-inf"},
    BadValue{"impact", "tau_over_T", "0"}, BadValue{"impact", "tau_over_T", "-1"},
    BadValue{"impact", "tau", "-2"}, BadValue{"impact", "tau", "nan"},
    BadValue{"impact", "x0", "1,2"}, BadValue{"impact", "v0", "inf"},
    BadValue{"impact", "orbit_period", "0"}, BadValue{"impact", "orbit_period", "1.5"},
    BadValue{"impact", "N", "0"}, BadValue{"impact", "N", "-5"}, BadValue{"impact", "N", "ten"},
    BadValue{"impact", "N", "3.5"}, BadValue{"impact", "N", ""}, BadValue{"impact", "N", "99999999999999999999"},
    BadValue{"impact", "events", "maybe"}, BadValue{"impact", "jacobian", "exact"},
    BadValue{"impact", "nev", "0"}, BadValue{"impact", "nev", "100000"}, BadValue{"impact", "nev", "many"},
    BadValue{"impact", "solver", "magic"}, BadValue{"impact", "orbit", "guess"},
    BadValue{"impact", "model", "duffing"},
    BadValue{"linear", "a", "nan"}, BadValue{"linear", "b", "b"}, BadValue{"linear", "tau", "0"},
    BadValue{"linear", "tau", "-1"}, BadValue{"linear", "period", "0"}, BadValue{"linear", "period", "inf"},
    BadValue{"mathieu", "kappa", "nan"}, BadValue{"mathieu", "delta", "x"}, BadValue{"mathieu", "eps", "inf"},
    BadValue{"mathieu", "b", "--"}));
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
