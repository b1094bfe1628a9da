// The `delayspec bench` command: contract keys, Krylov and dense agreeing at the same N, errors
// against the exact (Lambert W) values, per-row peak memory, the dense memory limit, bad input.
// No timing is asserted here (speed belongs to bench/ and docs/).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_support.hpp"

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::run;

}  // namespace

TEST(BenchCli, KrylovAndDenseAgreeAndMatchLambertW) {
  CliResult r =
      run({"bench", "--json", "--set", "model=linear", "--set", "a=-1", "--set", "b=-2", "--set", "Ns=100,400", "--set",
           "nev=4", "--set", "solvers=spectra,arpack,dense-lapack", "--set", "repeats=2"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["reference"], "exact");
  ASSERT_EQ(j["rows"].size(), 6u);
  for (const auto& row : j["rows"]) {
    for (const char* key : {"N", "solver", "seconds", "peak_bytes", "error", "operator_applications"})
      EXPECT_TRUE(row.contains(key)) << key;
    ASSERT_EQ(row["status"], "ok") << row.dump();
    // Two solves unless the first took 1 s or more (the cut-off; a loaded machine can get there).
    if (row["repeats"] != 2) {
      EXPECT_GE(row["seconds"].get<double>(), 1.0) << row.dump();
    }
    // seconds the fastest of them, seconds_slowest the slowest (the speed figure's bar)
    EXPECT_GE(row["seconds_slowest"].get<double>(), row["seconds"].get<double>()) << row.dump();
    // The discretisation error at N: C h^2 with C ~ 0.24 here (test_convergence: 3.9e-4 at N = 25),
    // so below 1e-4 at N = 100; the eigen-solver's own error (tol 1e-12) is far below it.
    EXPECT_LT(row["error"].get<double>(), 1e-4) << row.dump();
    if (row["solver"] != "dense-lapack") {
      // Krylov against dense at the same N: both solve the same matrix; Ritz residual tolerance
      // 1e-12 relative bounds the eigenvalue error of these well-separated values by ~1e-11.
      EXPECT_LT(row["deviation_from_dense"].get<double>(), 1e-10) << row.dump();
      EXPECT_LT(row["operator_applications"].get<long>(), row["N"].get<long>()) << "Krylov needs fewer than n";
    } else {
      // Dense forms the matrix: n = N + 1 applications, and holds at least one n x n matrix.
      const long n = row["dimension"].get<long>();
      EXPECT_EQ(row["operator_applications"].get<long>(), n);
      EXPECT_GE(row["peak_bytes"].get<long>(), static_cast<long>(0.5 * 8.0 * n * n))
          << "at least the matrix (half, for slack)";
    }
  }
}

TEST(BenchCli, DenseStopsAtTheMemoryLimitWithAMessage) {
  // N = 800, d = 2: n = 1602, 3 n^2 doubles = 59 MB > 10 MB: dense must not run.
  CliResult r = run({"bench", "--json", "--set", "model=mathieu", "--set", "Ns=800", "--set", "nev=2", "--set",
                     "solvers=spectra,dense-lapack", "--set", "dense_memory_limit_mb=10", "--set",
                     "reference=extrapolated"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["rows"].size(), 2u);
  EXPECT_EQ(j["rows"][0]["status"], "ok");
  EXPECT_EQ(j["rows"][1]["status"], "skipped");
  EXPECT_NE(j["rows"][1]["message"].get<std::string>().find("dense_memory_limit_mb"), std::string::npos);
  EXPECT_NE(r.err.find("skipped"), std::string::npos) << r.err;
  // One level, no exact values: no reference, and the output says so instead of inventing one.
  EXPECT_EQ(j["reference"], "none");
  EXPECT_TRUE(j["rows"][0]["error"].is_null());
}

TEST(BenchCli, TextTableAndCsv) {
  const auto dir = delayspec::testing::fresh_dir("bench_out");
  CliResult r = run({"bench", "--out", dir.string(), "--set", "model=mathieu", "--set", "Ns=50,100,200", "--set",
                     "nev=3", "--set", "solvers=spectra,dense", "--set", "reference=extrapolated"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("faster than dense-lapack"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("reference extrapolated"), std::string::npos) << r.out;
  std::ifstream csv(dir / "bench.csv");
  std::string line;
  int lines = 0;
  while (std::getline(csv, line))
    if (line.rfind("#", 0) != 0) ++lines;  // the metadata comment lines first (docs/formats.md)
  EXPECT_EQ(lines, 1 + 3 * 2);             // header, 3 N x 2 solvers
  // bench.json beside it, with the rows and the metadata, so that `plot DIR` draws the speed
  // figure after a bare `bench --out` (it used to need `run`)
  std::ifstream json_file(dir / "bench.json");
  ASSERT_TRUE(json_file) << "no bench.json";
  const auto j = nlohmann::json::parse(json_file);
  EXPECT_EQ(j["rows"].size(), 6u);
  EXPECT_EQ(j["metadata"]["command"], "bench");
  const CliResult plot = run({"plot", dir.string()});
  ASSERT_EQ(plot.status, 0) << plot.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "plots" / "speed_error.png")) << plot.out << plot.err;
  std::filesystem::remove_all(dir);
}

namespace {

struct BadValue {
  const char* key;
  const char* value;
};
void PrintTo(const BadValue& b, std::ostream* os) { *os << b.key << "=" << b.value; }
class BenchBadInput : public ::testing::TestWithParam<BadValue> {};

}  // namespace

TEST_P(BenchBadInput, ExitsTwoNamingKeyAndValue) {
  const BadValue b = GetParam();
  CliResult r =
      run({"bench", "--set", "model=linear", "--set", "Ns=20,40", "--set", std::string(b.key) + "=" + b.value});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(std::string("`") + b.key), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(b.value), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

// clang-format off
INSTANTIATE_TEST_SUITE_P(Keys, BenchBadInput, ::testing::Values(
    BadValue{"solvers", "magic"}, BadValue{"solvers", "spectra,spectra"}, BadValue{"solvers", ""},
    BadValue{"solver", "spectra"}, BadValue{"dense_memory_limit_mb", "-1"}, BadValue{"dense_memory_limit_mb", "lots"},
    BadValue{"nev", "40"}, BadValue{"nev", "0"}, BadValue{"reference", "best"}, BadValue{"Ns", "40,20"}, BadValue{"repeats", "0"}));
// clang-format on

TEST(BenchCli, MillingIsScoredAgainstTheSpectralReference) {
  // Milling's monodromy has no closed form; the engine's piecewise Chebyshev collocation
  // (spectral_reference.hpp, converged to ~1e-13) is the reference, named as such. The error at
  // N = 50 is the order-2 scheme's (~0.1 at a/D = 1), far above the reference's own error.
  CliResult r = run({"bench", "--json", "--set", "model=milling", "--set", "Ns=50,100", "--set", "nev=2", "--set",
                     "solvers=spectra"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("reference"), "exact");
  EXPECT_EQ(j.at("reference_source"), "spectral");
  ASSERT_EQ(j.at("rows").size(), 2u);
  const double e50 = j["rows"][0].at("error"), e100 = j["rows"][1].at("error");
  EXPECT_NEAR(e50 / e100, 4.0, 0.4) << "order 2 against the spectral value";
}
