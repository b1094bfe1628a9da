// `model = milling` from the command line: the keys reach the model (checked against the free
// oscillator's exact multipliers at depth 0), a chart over spindle speed and depth has its point
// count, bench runs the classic paths, and every milling key refuses bad values with exit 2.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <nlohmann/json.hpp>
#include <numbers>

#include "cli_test_support.hpp"

namespace {

using delayspec::testing::BadKey;
using delayspec::testing::CliResult;
using delayspec::testing::contains;
using delayspec::testing::run;
using delayspec::testing::with_sets;

// At depth 0 the cut vanishes: x'' + 2 zeta w x' + w^2 x = 0 over T = 60 / (teeth Omega), and
// the trapezoid's multipliers are exactly c^N, c = (1 + h l / 2) / (1 - h l / 2) for the roots l
// of l^2 + 2 zeta w l + w^2 (the Cayley transform, as in test_cli_chart_basin.cpp). This checks
// that spindle_rpm, teeth, omega_n and zeta reach the model with their units.
TEST(MillingCli, DepthZeroIsTheFreeOscillatorsCayleyTransform) {
  const double rpm = 7200, w = 2 * std::numbers::pi * 500, zeta = 0.02;
  const int teeth = 3, N = 60;
  CliResult r = run(
      with_sets({"floquet", "--json"}, {"model=milling", "depth=0", "spindle_rpm=7200", "teeth=3",
                                        "omega_n=" + std::to_string(w), "zeta=0.02", "N=60", "nev=2", "solver=dense",
                                        "grid=uniform"}));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["model"], "milling");
  EXPECT_EQ(j["dimension"], 2 * (N + 1));
  const double h = 60 / (teeth * rpm) / N;
  const std::complex<double> l(-zeta * w, w * std::sqrt(1 - zeta * zeta));
  const double expected = std::pow(std::abs((1.0 + h * l / 2.0) / (1.0 - h * l / 2.0)), N);
  // std::to_string(w) rounds omega_n to 6 decimals (relative 1e-10); the power N = 60 of a
  // modulus ~0.99 keeps it at that size.
  EXPECT_NEAR(j["multipliers"][0]["abs"].get<double>(), expected, 1e-9);
}

TEST(MillingCli, ChartOverSpindleSpeedAndDepthHasItsPoints) {
  CliResult r =
      run(with_sets({"chart", "--json"}, {"model=milling", "radial_immersion=0.05", "N=30", "solver=dense",
                                          "chart_x=spindle_rpm", "chart_x_range=5000,25000", "chart_x_points=4",
                                          "chart_y=depth", "chart_y_range=0,5e-3", "chart_y_points=3", "threads=1"}));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["points"], 12);
  EXPECT_EQ(j["failed_points"], 0);
  ASSERT_EQ(j["rows"].size(), 12u);
  // depth 0 is the free, damped oscillator: stable at every speed.
  for (const auto& p : j["rows"])
    if (p["y"].get<double>() == 0) {
      EXPECT_LT(p["spectral_radius"].get<double>(), 1);
    }
}

TEST(MillingCli, BenchRunsTheClassicPathsBesideDelayspec) {
  CliResult r = run(with_sets({"bench", "--json"},
                              {"model=milling", "Ns=20,40", "solvers=arpack,sdm0,fdm1", "nev=2", "reference=finest"}));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_FALSE(j["reference_values"].empty());
  int classic = 0;
  for (const auto& row : j["rows"]) {
    EXPECT_EQ(row["status"], "ok") << row.dump();
    // | |mu| - |ref| | <= |mu - ref| (triangle inequality): the modulus error never exceeds the
    // complex one (up to the rounding of the two divisions by |ref|).
    EXPECT_LE(row["abs_error"].get<double>(), row["error"].get<double>() * (1 + 1e-12) + 1e-15) << row.dump();
    if (row["solver"] == "sdm0" || row["solver"] == "fdm1") {
      ++classic;
      EXPECT_EQ(row["dimension"], 2 + row["N"].get<int>());  // x, v and m delayed positions
    }
  }
  EXPECT_EQ(classic, 4);
}

class MillingBadInput : public ::testing::TestWithParam<BadKey> {};

TEST_P(MillingBadInput, ExitsTwoNamingKeyAndValue) {
  delayspec::testing::expect_bad_input(GetParam(), {"model=milling", "N=10"});
}

// clang-format off
INSTANTIATE_TEST_SUITE_P(Keys, MillingBadInput, ::testing::Values(
    BadKey{"floquet", "depth", "-0.001", "`depth = -0.001`: must be >= 0"},
    BadKey{"floquet", "radial_immersion", "0", "`radial_immersion = 0`: must be in (0, 1]"},
    BadKey{"floquet", "radial_immersion", "1.5", "`radial_immersion = 1.5`: must be in (0, 1]"},
    BadKey{"floquet", "radial_immersion", "-0.2", "`radial_immersion = -0.2`: must be in (0, 1]"},
    BadKey{"floquet", "teeth", "0", "`teeth = 0`: must be between 1 and 30"},
    BadKey{"floquet", "teeth", "31", "`teeth = 31`: must be between 1 and 30"},
    BadKey{"floquet", "teeth", "2.5", "`teeth = 2.5`"},
    BadKey{"floquet", "spindle_rpm", "0", "`spindle_rpm = 0`: must be > 0"},
    BadKey{"floquet", "spindle_rpm", "-100", "`spindle_rpm = -100`: must be > 0"},
    BadKey{"floquet", "Kt", "nan", "`Kt = nan`: must be a finite number"},
    BadKey{"floquet", "Kn", "inf", "`Kn = inf`: must be a finite number"},
    BadKey{"floquet", "omega_n", "0", "`omega_n = 0`: must be > 0"},
    BadKey{"floquet", "zeta", "x", "`zeta = x`"},
    BadKey{"floquet", "mass", "0", "`mass = 0`: must be > 0"},
    BadKey{"floquet", "milling", "sideways", "`milling = sideways`: must be one of down, up"},
    BadKey{"lyapunov", "depth", "-1", "`depth = -1`: must be >= 0"},
    BadKey{"chart", "teeth", "0", "`teeth = 0`: must be between 1 and 30"},
    BadKey{"bench", "solvers", "sdm2", "`solvers = sdm2`"}));
// clang-format on

TEST(MillingCli, ClassicPathsRefuseModelsTheyDoNotCover) {
  CliResult impact = run({"bench", "--set", "solvers=sdm0", "--set", "Ns=20,40"});
  EXPECT_EQ(impact.status, 2);
  EXPECT_TRUE(contains(impact.err, "`solvers = sdm0`: the classic discretisations (sdm0, fdm1) need a linear model"))
      << impact.err;
  CliResult delay = run(with_sets({"bench"}, {"model=linear", "tau=1", "period=2", "solvers=fdm1", "Ns=20,40"}));
  EXPECT_EQ(delay.status, 2);
  EXPECT_TRUE(contains(delay.err, "need tau = T")) << delay.err;
}

}  // namespace

// Issue 61 item 9: `--help` prints `pitch_angles = equal` as the default; `--set` takes it and
// gives the equal pitch, the same numbers as without the key.
TEST(MillingCli, PitchAnglesEqualAsHelpPrintsItIsTheEqualPitch) {
  const CliResult plain = run({"floquet", "--json", "--set", "model=milling", "--set", "N=40"});
  const CliResult equal = run({"floquet", "--json", "--set", "model=milling", "--set", "N=40", "--set", "pitch_angles=equal"});
  ASSERT_EQ(plain.status, 0) << plain.err;
  ASSERT_EQ(equal.status, 0) << equal.err;
  EXPECT_EQ(nlohmann::json::parse(plain.out).at("multipliers"), nlohmann::json::parse(equal.out).at("multipliers"));
}
