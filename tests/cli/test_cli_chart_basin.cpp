// `delayspec chart` and `delayspec basin`: exact discrete values, serial = parallel, the period
// classification on synthetic sequences, and one test per bad-input path.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_support.hpp"
#include "scene/problem/section_period.hpp"

namespace fs = std::filesystem;

namespace {

using delayspec::testing::BadKey;
using delayspec::testing::CliResult;
using delayspec::testing::contains;
using delayspec::testing::run;
using delayspec::testing::with_sets;

// Spectral radius of the trapezoid rule's monodromy for x'' + kappa x' + delta x = 0 (b = eps = 0):
// the delay term vanishes, every step is u0' = C u0 with the Cayley transform
// C = (I - h/2 A)^{-1} (I + h/2 A), A = [[0, 1], [-delta, -kappa]], so the nonzero multipliers are
// c^K for the eigenvalues c = (1 + h lambda/2) / (1 - h lambda/2) of C, lambda those of A.
double trapezoid_radius(double kappa, double delta, int K, double h) {
  const std::complex<double> disc = std::sqrt(std::complex<double>(kappa * kappa / 4 - delta));
  double radius = 0;
  for (const auto lambda : {-kappa / 2 + disc, -kappa / 2 - disc})
    radius = std::max(radius, std::pow(std::abs((1.0 + h * lambda / 2.0) / (1.0 - h * lambda / 2.0)), K));
  return radius;
}

}  // namespace

TEST(ChartCli, UnforcedUndelayedMathieuMatchesCayleyTransformExactly) {
  const int N = 40;
  CliResult r = run(with_sets({"chart", "--json"}, {"model=mathieu", "eps=0", "b=0", "N=40", "solver=dense",
                                                    "chart_x=delta", "chart_x_range=-0.5,2", "chart_x_points=6",
                                                    "chart_y=kappa", "chart_y_range=0,0.4", "chart_y_points=3"}));
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["rows"].size(), 18u);
  const double h = 2 * M_PI / N;  // tau = period = 2 pi, K = N steps per map
  for (const auto& row : j["rows"]) {
    const double delta = row["x"], kappa = row["y"];
    const double expected = trapezoid_radius(kappa, delta, N, h);
    // The dense eigen-solve of an 82 x 82 matrix of norm O(1): backward-stable, the simple
    // leading eigenvalue is accurate to ~ n eps cond; 1e-9 relative leaves ample room.
    EXPECT_NEAR(row["spectral_radius"].get<double>(), expected, 1e-9 * expected) << delta << " " << kappa;
  }
}

TEST(ChartCli, ParallelEqualsSerialAndCsvHasGridBlocks) {
  const fs::path dir = delayspec::testing::fresh_dir("chart_csv");
  std::vector<std::string> sets = {"model=mathieu", "kappa=0.1",        "eps=1",           "N=20",
                                   "solver=dense",  "chart_x_points=4", "chart_y_points=3"};
  auto serial = with_sets({"chart", "--json"}, sets);
  serial.insert(serial.end(), {"--set", "threads=1"});
  auto parallel = with_sets({"chart", "--json", "--out", dir.string()}, sets);
  parallel.insert(parallel.end(), {"--set", "threads=3"});
  CliResult a = run(serial), b = run(parallel);
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(b.status, 0) << b.err;
  auto ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
  // The same computation per point regardless of the thread that ran it: bitwise equal.
  EXPECT_EQ(ja["rows"], jb["rows"]);
  std::ifstream csv(dir / "chart.csv");
  std::string line;
  int blank = 0, data = 0;
  bool header = false;
  while (std::getline(csv, line)) {
    if (line.empty()) ++blank;
    else if (line == "delta,b,spectral_radius,error_estimate,undecided,angle") header = true;  // error_bars = on
    else if (line[0] != '#') ++data;
  }
  EXPECT_TRUE(header);
  EXPECT_EQ(data, 12);
  EXPECT_EQ(blank, 2);  // one blank line between consecutive y blocks
}

TEST(SectionPeriod, FindsSmallestPeriodOrNone) {
  auto sequence = [](int period, int length, double noise) {
    std::vector<Eigen::VectorXd> S;
    for (int j = 0; j < length; ++j) {
      Eigen::VectorXd v(3);
      v << (j % period), 2.0 * (j % period) - 1, 0.5;
      v[2] += noise * ((j * 7919) % 13 - 6) / 6.0;  // deterministic jitter of size <= noise
      S.push_back(v);
    }
    return S;
  };
  EXPECT_EQ(delayspec::cli::section_period(sequence(1, 17, 0), 8, 1e-6), 1);
  EXPECT_EQ(delayspec::cli::section_period(sequence(3, 17, 0), 8, 1e-6), 3);
  EXPECT_EQ(delayspec::cli::section_period(sequence(5, 17, 1e-8), 8, 1e-6), 5);  // jitter below tolerance
  EXPECT_EQ(delayspec::cli::section_period(sequence(5, 17, 1e-3), 8, 1e-6), 0);  // jitter above it
  EXPECT_EQ(delayspec::cli::section_period(sequence(9, 17, 0), 8, 1e-6), 0);     // longer than max_period
  EXPECT_EQ(delayspec::cli::section_period(sequence(6, 17, 0), 8, 1e-6), 6);
  EXPECT_THROW(delayspec::cli::section_period(sequence(1, 16, 0), 8, 1e-6), delayspec::BadInput);
}

TEST(BasinCli, NeighbourhoodOfStablePeriodOneOrbitIsPeriodOne) {
  // The default scene's orbit (k = 0.2, tau = T) is stable (|mu_1| < 1, FloquetCli.DefaultSceneRuns);
  // histories within 0.01 of it converge to it.
  CliResult r = run(with_sets({"basin", "--json"},
                              {"k=0.2", "N=40", "basin_x_range=-0.0666,-0.0466", "basin_y_range=1.0001,1.0201",
                               "basin_x_points=2", "basin_y_points=2", "basin_transient=300", "basin_max_period=5"}));
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  for (const auto& row : j["rows"]) EXPECT_EQ(row["period"], 1) << row.dump();
  EXPECT_EQ(j["counts"]["1"], 4);
}

class GridBadInput : public ::testing::TestWithParam<BadKey> {};

TEST_P(GridBadInput, ExitsTwoNamingKeyAndValue) {
  delayspec::testing::expect_bad_input(GetParam(), {"model=mathieu", "N=8", "solver=dense"});
}

// clang-format off
INSTANTIATE_TEST_SUITE_P(Keys, GridBadInput, ::testing::Values(
    BadKey{"chart", "chart_x_range", "1", "`chart_x_range = 1`: must be two numbers"},
    BadKey{"chart", "chart_x_range", "2,1", "`chart_x_range = 2,1`: must be two numbers [min, max] with min < max"},
    BadKey{"chart", "chart_y_range", "0,x", "`chart_y_range = 0,x`: `x` is not a finite number"},
    BadKey{"chart", "chart_y_range", "0,inf", "`chart_y_range = 0,inf`"},
    BadKey{"chart", "chart_x_points", "1", "`chart_x_points = 1`: must be between 2 and 100000"},
    BadKey{"chart", "chart_y_points", "many", "`chart_y_points = many`: not an integer"},
    BadKey{"chart", "chart_x", "b", "`chart_x = chart_y = b`"},
    BadKey{"chart", "chart_x", "zeta", "`chart_x = zeta`: not a numeric parameter of model mathieu"},
    BadKey{"chart", "chart_y", "N", "`chart_y = N`: not a numeric parameter"},
    BadKey{"chart", "threads", "-1", "`threads = -1`: must be between 0 and 4096"},
    BadKey{"chart", "chart_xpoints", "3", "unknown key `chart_xpoints`"},
    BadKey{"basin", "basin_transient", "-1", "`basin_transient = -1`"},
    BadKey{"basin", "basin_max_period", "0", "`basin_max_period = 0`"},
    BadKey{"basin", "basin_tolerance", "0", "`basin_tolerance = 0`"},
    BadKey{"basin", "basin_x", "kappa", "`basin_y = v0`: not a numeric parameter of model mathieu"},
    BadKey{"basin", "basin_x_range", "3,3", "`basin_x_range = 3,3`"}));
// clang-format on

// Issue 61 item 7: a chart of an autonomous model follows the map's fixed point (Mackey-Glass:
// the equilibrium, over T = tau); it says so and where orbits and equilibria are followed instead.
TEST(ChartCli, AnAutonomousModelSaysWhatIsCharted) {
  const CliResult r = run({"chart", "--set", "model=mackey-glass", "--set", "N=20", "--set", "chart_x=beta", "--set",
                           "chart_x_range=0.19,0.2", "--set", "chart_x_points=2", "--set", "chart_y=gamma", "--set",
                           "chart_y_range=0.09,0.1", "--set", "chart_y_points=2", "--set", "threads=1"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "chart: note: model `mackey-glass` is autonomous")) << r.err;
  EXPECT_TRUE(contains(r.err, "`floquet` with `period_guess`")) << r.err;
}
