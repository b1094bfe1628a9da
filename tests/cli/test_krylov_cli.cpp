// `delayspec floquet` with the Krylov solvers: the JSON contract (sorted multipliers, solver,
// operator_applications, converged, restarts, residuals), exit 3 on forced non-convergence,
// and exit 2 naming key and value for every bad Krylov key.
#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_support.hpp"
#include "delayspec_test_paths.hpp"

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::run;

const std::string kScene = DELAYSPEC_SOURCE_DIR "/data/scenes/default.toml";

}  // namespace

TEST(KrylovCli, JsonContractForBothBackends) {
  for (const char* solver : {"spectra", "arpack"}) {
    CliResult r =
        run({"floquet", kScene, "--json", "--set", "N=80", "--set", "nev=8", "--set", std::string("solver=") + solver});
    ASSERT_EQ(r.status, 0) << r.err;
    auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["solver"], solver);
    for (const char* key : {"model", "N", "dimension", "multipliers", "seconds", "operator_applications", "converged",
                            "restarts", "residuals", "ncv", "tol", "iterations", "seed"})
      EXPECT_TRUE(j.contains(key)) << key;
    ASSERT_EQ(j["multipliers"].size(), 8u);
    ASSERT_EQ(j["residuals"].size(), 8u);
    EXPECT_GE(j["converged"].get<int>(), 8);
    for (size_t i = 0; i < 8; ++i) {
      if (i + 1 < 8) {
        EXPECT_GE(j["multipliers"][i]["abs"].get<double>(), j["multipliers"][i + 1]["abs"].get<double>());
      }
      EXPECT_LE(j["residuals"][i].get<double>(), 1e-9);  // stopping rule 1e-12 plus rounding (test_krylov.cpp)
    }
  }
}

TEST(KrylovCli, DefaultSceneUsesSpectra) {
  CliResult r = run({"floquet", kScene, "--json", "--set", "N=60"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["solver"], "spectra");
}

TEST(KrylovCli, ForcedNonConvergenceExitsThree) {
  for (const char* solver : {"spectra", "arpack"}) {
    CliResult r = run({"floquet", kScene, "--json", "--set", "N=100", "--set", "nev=10", "--set", "ncv=12", "--set",
                       "max_restarts=0", "--set", std::string("solver=") + solver});
    EXPECT_EQ(r.status, 3) << solver << ": " << r.err;
    EXPECT_NE(r.err.find("did not converge"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << "no partial result: " << r.out;
  }
}

// Issue 31: when Spectra did not converge, floquet retried with ncv doubled, and the retry's
// failure was the only message: "2 Arnoldi iterations (max_iterations = 1 ..., ncv = 16)" for a
// user's ncv = 8, with no word of the retry. The message now says it was the retry, names both
// ncv and gives each attempt's count, which cannot exceed max_iterations.
TEST(KrylovCli, FailedRetryNamesBothAttemptsWithCountsWithinTheLimit) {
  const CliResult r = run({"floquet", kScene, "--set", "N=100", "--set", "nev=4", "--set", "ncv=8", "--set",
                           "max_restarts=0", "--set", "solver=spectra"});
  ASSERT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("the retry with ncv = 16"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the first attempt, with ncv = 8"), std::string::npos) << r.err;
  // One count per attempt, each against the limit it names.
  const std::string count = " Arnoldi iterations (max_iterations = ";
  int attempts = 0;
  for (size_t at = r.err.find(count); at != std::string::npos; at = r.err.find(count, at + 1)) {
    ++attempts;
    const size_t start = r.err.rfind("after ", at) + 6;
    const int iterations = std::stoi(r.err.substr(start, at - start));
    const int limit = std::stoi(r.err.substr(at + count.size()));
    EXPECT_EQ(limit, 1) << r.err;
    EXPECT_GE(iterations, 1) << r.err;
    EXPECT_LE(iterations, limit) << r.err;
  }
  EXPECT_EQ(attempts, 2) << r.err;
}

TEST(KrylovCli, BadKrylovKeysExitTwoNamingKeyAndValue) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"ncv", "-1"},           {"ncv", "7"},  // 7 < nev + 2 = 8
      {"ncv", "many"},         {"tol", "0"},   {"tol", "-1e-9"}, {"tol", "nan"}, {"tol", "x"}, {"max_restarts", "-1"},
      {"max_restarts", "1.5"}, {"seed", "-3"}, {"seed", "abc"}};
  for (const auto& [key, value] : bad) {
    CliResult r = run(
        {"floquet", "--set", "model=mathieu", "--set", "N=20", "--set", "solver=arpack", "--set", key + "=" + value});
    EXPECT_EQ(r.status, 2) << key << "=" << value << ": " << r.err;
    EXPECT_NE(r.err.find("`" + key), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(value), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty());
  }
}

TEST(KrylovCli, NoMultiplierFailingItsResidualIsPrintedWithExitZero) {
  // Issue 13 item 1, as a user ran it: x' = 5 x, N = 50. mu_1 = ((1 + 0.05) / (1 - 0.05))^50
  // exactly (rank-one monodromy); the default solver printed -223.1 + 441.0i with exit 0.
  const double exact = std::pow(1.05 / 0.95, 50);
  for (const char* solver : {"spectra", "arpack"}) {
    CliResult r = run({"floquet", "--json", "--set", "model=linear", "--set", "a=5", "--set", "b=0", "--set", "N=50",
                       "--set", "nev=1", "--set", std::string("solver=") + solver});
    ASSERT_EQ(r.status, 0) << r.err;
    auto j = nlohmann::json::parse(r.out);
    EXPECT_NEAR(j["multipliers"][0]["re"].get<double>(), exact, 1e-12 * exact) << solver;
    EXPECT_EQ(j["multipliers"][0]["im"].get<double>(), 0.0) << solver;
    EXPECT_LE(j["residuals"][0].get<double>(), 1e-8) << solver;
    // nev = 2: the second multiplier is 0 (rank one): at the round-off level, with a note, and not
    // printed as a value (issue 32, item 2): `resolved` false, its bound at the round-off level
    // (10 sqrt(n) eps |mu_1| ~ 2e-14 |mu_1|; 1e-10 |mu_1| would be a bound that says nothing).
    r = run({"floquet", "--json", "--set", "model=linear", "--set", "a=5", "--set", "b=0", "--set", "N=50", "--set",
             "nev=2", "--set", std::string("solver=") + solver});
    ASSERT_EQ(r.status, 0) << r.err;
    j = nlohmann::json::parse(r.out);
    EXPECT_FALSE(j["multipliers"][1]["resolved"].get<bool>()) << solver;
    EXPECT_TRUE(j["multipliers"][1]["abs"].is_null()) << solver;
    EXPECT_GT(j["multipliers"][1]["bound"].get<double>(), 0.0) << solver;
    EXPECT_LT(j["multipliers"][1]["bound"].get<double>(), 1e-10 * exact) << solver;
    EXPECT_TRUE(j["multipliers"][0]["resolved"].get<bool>()) << solver;
    EXPECT_NE(j["note"].get<std::string>().find("round-off level"), std::string::npos) << solver;
  }
  // A bad bound is bad input naming the key.
  CliResult bad = run({"floquet", "--set", "model=linear", "--set", "N=20", "--set", "residual_bound=-1"});
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("`residual_bound = -1`"), std::string::npos) << bad.err;
}
