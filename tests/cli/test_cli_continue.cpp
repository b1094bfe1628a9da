// `delayspec continue`: the JSON result and files against the exact stability boundary of a
// linear DDE, and every bad-input and failure path of the issue (exit 2 naming the key and value,
// exit 3 naming the residual or the point reached, with the branch so far written).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"
#include "delayspec/errors.hpp"
#include "delayspec_test_paths.hpp"

namespace {

namespace fs = std::filesystem;
using delayspec::testing::CliResult;
using delayspec::testing::run;
using std::numbers::pi;

// x' = -x + b x(t - tau), tau = 2 pi / (3 sqrt 3): a pair of roots +-i sqrt 3 crosses at b = -2,
// angle sqrt 3 tau = 2 pi / 3 per period T = tau (test_continuation.cpp).
const double kTau = 2 * pi / (3 * std::sqrt(3.0));

std::vector<std::string> linear_args(std::vector<std::string> extra) {
  std::vector<std::string> args = {"continue",
                                   "--set",
                                   "model=linear",
                                   "--set",
                                   "a=-1",
                                   "--set",
                                   "tau=" + delayspec::format_number(kTau),
                                   "--set",
                                   "continue_key=b",
                                   "--set",
                                   "continue_from=-1.5",
                                   "--set",
                                   "continue_to=-2.5"};
  for (auto& e : extra) args.push_back(std::move(e));
  return args;
}

fs::path scratch(const std::string& name) {
  return delayspec::testing::scratch_path("continue_" + name);
}

std::vector<std::string> data_lines(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') lines.push_back(line);
  return lines;
}

std::string read_all(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST(ContinueCli, NeimarkSackerOfLinearDdeWithErrorBars) {
  CliResult r =
      run(linear_args({"--set", "continue_Ns=100,200,400,800", "--set", "continue_tolerance=1e-13", "--json"}));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["continue_key"], "b");
  EXPECT_EQ(j["N"], 800);
  EXPECT_EQ(j["end"], "to");
  ASSERT_GE(j["points"].size(), 3u);
  EXPECT_EQ(j["points"].front()["parameter"], -1.5);
  EXPECT_EQ(j["points"].back()["parameter"], -2.5);
  for (const auto& p : j["points"]) {
    // stable exactly while b > -2 (up to the discrete boundary's O(h^2) shift, far below the steps)
    EXPECT_EQ(p["stable"].get<bool>(), p["parameter"].get<double>() > -2) << p["parameter"];
    EXPECT_EQ(p["multipliers"].size(), 6u);
    EXPECT_TRUE(p["multipliers"][0].contains("abs"));
  }
  ASSERT_EQ(j["bifurcations"].size(), 1u);
  const auto& b = j["bifurcations"][0];
  EXPECT_EQ(b["type"], "neimark-sacker");
  ASSERT_EQ(b["by_N"].size(), 4u);
  EXPECT_EQ(b["by_N"][3]["N"], 800);
  EXPECT_EQ(b["by_N"][3]["parameter"], b["parameter"]);
  const double h = kTau / 800;
  EXPECT_NEAR(b["angle"].get<double>(), 2 * pi / 3, 5 * h * h);  // the angle's O(h^2) error
  EXPECT_NEAR(b["observed_order"].get<double>(), 2, 0.05);
  // honest: the extrapolated boundary within its estimate of -2, the estimate <= 1e-8
  EXPECT_LE(std::abs(b["extrapolated"].get<double>() + 2), b["error_estimate"].get<double>());
  EXPECT_LE(b["error_estimate"].get<double>(), 1e-8);
  // the angle extrapolated with the location (issue 32): within its estimate of 2 pi / 3, which is
  // far below the finest level's own O(h^2) error
  const double angle = b["angle_extrapolated"], angle_bar = b["angle_error_estimate"];
  EXPECT_LE(std::abs(angle - 2 * pi / 3), angle_bar + 1e-12);
  EXPECT_LT(angle_bar, 1e-2 * std::abs(b["angle"].get<double>() - 2 * pi / 3));
  // |mu| = 1 at the located point, to the location tolerance times d|mu|/db = O(1)
  EXPECT_NEAR(b["multipliers"][0]["abs"].get<double>(), 1, 1e-11);
}

// Issue 32, item 3: the location tolerance set a floor under every bar. At the default
// 1e-10 |to - from| the Neimark-Sacker point of x' = -x + b x(t - tau) (exactly b = -2) over
// N = 100 .. 1600 got a bar of 1.95e-10 for an error of 4.4e-13; with continue_Ns the locations
// are now narrowed on towards 1e-13 |to - from| and the bar is 1.95e-13 for 3.0e-14. Covering,
// below 1e-12, and within 10x of the error or of the location's own floor (1e-13 |to - from|:
// the extrapolation cannot be vouched for below the accuracy of its inputs). And every point's
// verdict for N -> infinity: the NS interval is ~1e-13 wide, so none is undecided.
TEST(ContinueCli, NeimarkSackerBarIsTightAtTheDefaultTolerance) {
  CliResult r = run(linear_args({"--set", "continue_Ns=100,200,400,800,1600", "--json"}));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["bifurcations"].size(), 1u);
  const auto& b = j["bifurcations"][0];
  const double error = std::abs(b["extrapolated"].get<double>() + 2), bar = b["error_estimate"].get<double>();
  EXPECT_LE(error, bar) << b;
  EXPECT_LT(bar, 1e-12) << b;
  EXPECT_LE(bar, 10 * std::max(error, 1e-13)) << b;
  for (const auto& p : j["points"])
    EXPECT_EQ(p["verdict"], p["parameter"].get<double>() > -2 ? "stable" : "unstable") << p["parameter"];
  EXPECT_NE(j["verdicts_note"].get<std::string>().find("0 of"), std::string::npos) << j["verdicts_note"];
  // Two levels: no bar, so no point is decided.
  r = run(linear_args({"--set", "continue_Ns=100,200", "--json"}));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto two = nlohmann::json::parse(r.out);  // kept: a range-for over a temporary's member dangles
  for (const auto& p : two["points"]) EXPECT_EQ(p["verdict"], "undecided");
}

// The error expansion has one home (error_expansion.hpp) for every analysis. Milling at a/D = 0.05
// stepped with events = off on a uniform grid (the tooth's entry and exit inside steps): the
// period-doubling depth carries a wandering h^2 term. continue assumed h^2, h^4, ... there (its
// own copy of the rule looked at switches in the state only) and printed 0.0040630 +- 1.4e-5 over
// N = 100, 200, 400, 2.8e-5 from the depth 0.00409071 (events on, N = 800, 1600, 3200: +- 8.3e-8):
// a bar that did not cover. Now, as floquet's error bars: no estimate, and why; with the switches
// on nodes (the aligned grid) the order-1 expansion gives one that covers.
TEST(ContinueCli, MillingWithEventsOffHasFloquetsErrorExpansion) {
  const std::string scene = std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/milling_point.toml";
  const double reference = 0.0040907106;  // events on, N = 800 .. 3200: +- 8.3e-8
  for (const char* grid : {"uniform", "aligned"}) {
    const CliResult r = run({"continue", scene, "--set", "radial_immersion=0.05", "--set", "continue_key=depth", "--set",
                             "continue_from=1e-4", "--set", "continue_to=2e-2", "--set", "nev=4", "--set", "events=off",
                             "--set", std::string("grid=") + grid, "--set", "continue_Ns=100,200,400", "--json"});
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["bifurcations"].size(), 1u) << grid;
    const auto& b = j["bifurcations"][0];
    EXPECT_EQ(b["type"], "period-doubling");
    if (std::string(grid) == "uniform") {
      EXPECT_TRUE(b["error_estimate"].is_null()) << b;
      EXPECT_NE(b["note"].get<std::string>().find("no error estimate"), std::string::npos) << b;
    } else {
      ASSERT_FALSE(b["error_estimate"].is_null()) << b;
      EXPECT_LE(std::abs(b["extrapolated"].get<double>() - reference), b["error_estimate"].get<double>()) << b;
    }
  }
}

// Issue 32, item 4: on the PWSDDE period-2 branch a second contact region appears at k = 0.1767
// on an orbit already in contact (`floquet data/scenes/pwsdde-period2.toml --set N=800`: 1
// contact at k = 0.1767, 2 at 0.1768), which the sign of max H does not see: continue reported only
// the fold after it. It is a grazing of its own now, found at every level, converging at the
// trapezoid's order 2 (the hump's max from the cubic Hermite interpolant, O(h^4) beyond the orbit's
// O(h^2)): over N = 100, 200, 400 order 1.95; by hand over 200, 400, 800, 2.08 (0.1767247,
// 0.1767128, 0.1767099; N = 800 took 24 s when the corrector was a sparse LU, whose factors fill
// in with the fractional delay; with GMRES on the condensed system, the default, 0.6 s).
TEST(ContinueCli, ASecondContactRegionIsAGrazingThatConvergesAtOrderTwo) {
  const std::string scene = std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/continue_pwsdde_k.toml";
  const CliResult r = run({"continue", "--json", scene, "--set", "continue_from=0.1766", "--set", "continue_to=0.1768",
                           "--set", "k=0.1766", "--set", "orbit_guess_periods=300", "--set", "continue_Ns=100,200,400",
                           "--set", "continue_step=1e-4", "--set", "continue_step_max=2e-4"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["bifurcations"].size(), 1u) << j["bifurcations"];
  const auto& b = j["bifurcations"][0];
  EXPECT_EQ(b["type"], "grazing");
  EXPECT_NE(b["note"].get<std::string>().find("a second contact region"), std::string::npos) << b["note"];
  ASSERT_EQ(b["by_N"].size(), 3u);
  EXPECT_NEAR(b["observed_order"].get<double>(), 2, 0.3) << b;
  EXPECT_NEAR(b["parameter"].get<double>(), 0.17675, 5e-5);  // between the 0.1767 and 0.1768
  // one region before it, two after
  EXPECT_EQ(j["points"].front()["measures"]["contact_regions"], 1);
  EXPECT_EQ(j["points"].back()["measures"]["contact_regions"], 2);
}

// Issue 36, item 3: the whole PWSDDE branch (fractional delay, impacts, a fold where the orbit
// meets its copy shifted by one forcing period, two grazings) with each corrector: the same points, multipliers and
// located bifurcations at every level, to 1e-9 (test_condensed_bordered.cpp says why), and the
// Krylov path factors no matrix.
TEST(ContinueCli, KrylovAndLuCorrectorsGiveTheSamePwsddeBranch) {
  const std::string scene = std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/continue_pwsdde_k.toml";
  auto branch = [&](const std::string& solver) {
    const CliResult r =
        run({"continue", "--json", scene, "--set", "continue_Ns=50,100", "--set", "continue_solver=" + solver});
    EXPECT_EQ(r.status, 0) << r.err;
    return nlohmann::json::parse(r.out);
  };
  const auto lu = branch("lu"), krylov = branch("krylov");
  EXPECT_GT(lu["cost_finest_N"]["factorisations"].get<long>(), 0);
  EXPECT_EQ(lu["cost_finest_N"]["gmres_products"].get<long>(), 0);
  EXPECT_EQ(krylov["cost_finest_N"]["factorisations"].get<long>(), 0);
  EXPECT_GT(krylov["cost_finest_N"]["gmres_products"].get<long>(), 0);
  EXPECT_EQ(krylov["cost_finest_N"]["unknowns"], lu["cost_finest_N"]["unknowns"]);
  ASSERT_EQ(lu["points"].size(), krylov["points"].size());
  for (size_t i = 0; i < lu["points"].size(); ++i) {
    const auto &a = lu["points"][i], &b = krylov["points"][i];
    EXPECT_NEAR(a["parameter"].get<double>(), b["parameter"].get<double>(), 1e-9) << "point " << i;
    ASSERT_EQ(a["multipliers"].size(), b["multipliers"].size()) << "point " << i;
    for (size_t m = 0; m < a["multipliers"].size(); ++m) {
      EXPECT_NEAR(a["multipliers"][m]["re"].get<double>(), b["multipliers"][m]["re"].get<double>(), 1e-9);
      EXPECT_NEAR(a["multipliers"][m]["im"].get<double>(), b["multipliers"][m]["im"].get<double>(), 1e-9);
    }
  }
  ASSERT_EQ(lu["bifurcations"].size(), krylov["bifurcations"].size());
  ASSERT_GE(lu["bifurcations"].size(), 2u);  // grazing and fold at least
  for (size_t i = 0; i < lu["bifurcations"].size(); ++i) {
    const auto &a = lu["bifurcations"][i], &b = krylov["bifurcations"][i];
    EXPECT_EQ(a["type"], b["type"]);
    ASSERT_EQ(a["by_N"].size(), b["by_N"].size());
    for (size_t k = 0; k < a["by_N"].size(); ++k)
      EXPECT_NEAR(a["by_N"][k]["parameter"].get<double>(), b["by_N"][k]["parameter"].get<double>(), 1e-9)
          << a["type"] << " at N = " << a["by_N"][k]["N"];
  }
}

TEST(ContinueCli, WritesBranchAndBifurcationFilesWithMetadata) {
  const fs::path dir = scratch("files");
  CliResult r = run(linear_args({"--set", "N=200", "--out", dir.string(), "--json"}));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const std::string branch = read_all(dir / "branch.csv");
  EXPECT_NE(branch.find("# command: continue"), std::string::npos) << branch;
  EXPECT_NE(branch.find("# continue_key = b"), std::string::npos) << branch;
  const auto rows = data_lines(dir / "branch.csv");
  ASSERT_EQ(rows.size(), j["points"].size() + 1);  // header + one row per point
  EXPECT_EQ(rows[0].rfind("parameter,stable,unstable,abs_mu1,max_y1,min_y1,max_H,contact_time", 0), 0u) << rows[0];
  const auto bifs = data_lines(dir / "bifurcations.csv");
  ASSERT_EQ(bifs.size(), 2u);
  EXPECT_EQ(bifs[1].rfind("neimark-sacker,", 0), 0u) << bifs[1];
  EXPECT_TRUE(fs::exists(dir / "continue.json"));
  EXPECT_TRUE(fs::exists(dir / "complete.json"));
  // plot draws the branch and |mu_1| from these files
  CliResult plot = run({"plot", dir.string()});
  ASSERT_EQ(plot.status, 0) << plot.err;
  EXPECT_TRUE(fs::exists(dir / "plots" / "branch.png"));
  EXPECT_TRUE(fs::exists(dir / "plots" / "branch_mu1.svg"));
  const std::string script = read_all(dir / "plots" / "branch.gp");
  EXPECT_NE(script.find("'neimark-sacker'"), std::string::npos) << script;  // the bifurcation is marked
  fs::remove_all(dir);
}

struct BadContinue {
  std::vector<std::string> sets;
  const char* named;  // the message names this
};

class ContinueBadInput : public ::testing::TestWithParam<BadContinue> {};

TEST_P(ContinueBadInput, ExitsTwoNamingTheKey) {
  std::vector<std::string> args = {"continue", "--set", "model=linear"};
  for (const auto& s : GetParam().sets) args.insert(args.end(), {"--set", s});
  CliResult r = run(args);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(GetParam().named), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

INSTANTIATE_TEST_SUITE_P(
    Keys, ContinueBadInput,
    ::testing::Values(
        BadContinue{{"continue_from=0", "continue_to=1"}, "continue_key"},
        BadContinue{{"continue_key=bb", "continue_from=0", "continue_to=1"}, "`continue_key = bb`: not a model parameter"},
        BadContinue{{"continue_key=b", "continue_from=0.3", "continue_to=0.3"}, "empty range"},
        BadContinue{{"continue_key=b", "continue_to=0.3"}, "continue_from"},
        BadContinue{{"continue_key=N", "continue_from=10", "continue_to=20"}, "`continue_key = N`"},
        BadContinue{{"continue_key=b", "continue_from=0", "continue_to=1", "continue_Ns=400,200"}, "continue_Ns"},
        BadContinue{{"continue_key=b", "continue_from=0", "continue_to=1", "continue_step=-1"}, "`continue_step = -1`"},
        BadContinue{{"continue_key=b", "continue_from=0", "continue_to=1", "continue_max_points=1"},
                    "`continue_max_points = 1`"},
        BadContinue{{"continue_key=b", "continue_from=0", "continue_to=1", "continue_solver=qr"}, "continue_solver"},
        // a key that changes the grid (the period of the map: K steps per map)
        BadContinue{{"continue_key=period", "continue_from=1", "continue_to=2", "N=20"},
                    "must not change the size of the discrete problem"}));

TEST(ContinueCli, StartWhereNewtonFailsExitsThreeNamingTheResidual) {
  // Newton from the first period after rest (orbit_guess_periods = 0) with one iteration allowed
  CliResult r =
      run({"continue", "--set", "orbit=newton", "--set", "orbit_max_iterations=1", "--set", "orbit_guess_periods=0",
           "--set", "continue_key=k", "--set", "continue_from=0.2", "--set", "continue_to=0.3", "--set", "N=50"});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("|F|_inf"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(ContinueCli, StepThatCannotBeReducedExitsThreeWithTheBranchSoFar) {
  // The damping continued from 0.02 towards -0.02: the model exists only for zeta >= 0, so the
  // branch shrinks its step at zeta = 0 until it is below continue_step_min.
  const fs::path dir = scratch("failure");
  CliResult r = run({"continue", "--set", "orbit=newton", "--set", "e=1.3", "--set", "continue_key=zeta", "--set",
                     "continue_from=0.02", "--set", "continue_to=-0.02", "--set", "N=50", "--set", "nev=2", "--out",
                     dir.string()});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("step below continue_step_min"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("`zeta = -"), std::string::npos) << r.err;  // the model's own message
  const std::string branch = read_all(dir / "branch.csv");
  EXPECT_NE(branch.find("# INCOMPLETE"), std::string::npos) << branch;
  const auto rows = data_lines(dir / "branch.csv");
  ASSERT_GE(rows.size(), 3u);
  // the last point reached lies just above zeta = 0, and is the one the message names
  const std::string last = rows.back().substr(0, rows.back().find(','));
  EXPECT_GE(std::stod(last), 0);
  EXPECT_LT(std::stod(last), 1e-3);
  EXPECT_NE(r.err.find("at parameter " + last), std::string::npos) << r.err;
  const std::string complete = read_all(dir / "complete.json");
  EXPECT_NE(complete.find("\"exit_status\": 3"), std::string::npos) << complete;
  fs::remove_all(dir);
}

// continue_switch: the period-1 orbit of the PWSDDE-cont system (tau = 3.8, fractional delay)
// continued in k down from 0.25 loses stability by a period doubling near k = 0.177; the branch
// switched there must reach, at k = 0.12, the period-2 orbit that `floquet` finds on its own from
// a simulated guess (data/scenes/pwsdde-period2.toml): same multipliers, to the orbits' tolerance.
TEST(ContinueCli, SwitchAtPeriodDoublingReachesTheKnownPeriodTwoOrbit) {
  const std::string scene = std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/pwsdde-period2.toml";
  CliResult r = run({"continue", scene,
                     "--set",    "orbit_period=1",
                     "--set",    "k=0.25",
                     "--set",    "N=100",
                     "--set",    "orbit_guess_periods=200",
                     "--set",    "continue_key=k",
                     "--set",    "continue_from=0.25",
                     "--set",    "continue_to=0.12",
                     "--set",    "continue_switch=true",
                     "--json",   "--quiet"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_GE(j["bifurcations"].size(), 1u);
  EXPECT_EQ(j["bifurcations"][0]["type"], "period-doubling");
  ASSERT_EQ(j["switched"].size(), 1u);
  const auto& sw = j["switched"][0];
  EXPECT_EQ(sw["orbit_period"], 2);
  EXPECT_EQ(sw["from_parameter"], j["bifurcations"][0]["parameter"]);
  ASSERT_EQ(sw["end"], "to");
  const auto& last = sw["points"].back();
  EXPECT_EQ(last["parameter"], 0.12);
  // the first point is the period doubling itself: multiplier (-1)^2 = +1 of the doubled problem
  EXPECT_NEAR(sw["points"][0]["multipliers"][0]["abs"].get<double>(), 1, 1e-8);
  CliResult f = run({"floquet", scene, "--set", "N=100", "--json"});
  ASSERT_EQ(f.status, 0) << f.err;
  const auto fj = nlohmann::json::parse(f.out);
  for (int i = 0; i < 2; ++i) {
    // both orbits to |F| <= 1e-12 (1 + |x|): the multipliers agree far below 1e-9
    EXPECT_NEAR(last["multipliers"][i]["re"].get<double>(), fj["multipliers"][i]["re"].get<double>(), 1e-9) << i;
    EXPECT_NEAR(last["multipliers"][i]["im"].get<double>(), fj["multipliers"][i]["im"].get<double>(), 1e-9) << i;
  }
}

namespace {

TEST(ContinueCli, StartsAtTheEndOfAKeysRange) {
  // milling's depth from 0: the central difference for F_p asked for depth = -6e-9 and the start
  // failed with "the model rejects parameter 0" (issue 32, item 4). The one-sided difference at
  // the bound: the branch starts, and the Neimark-Sacker point is where a start inside the range
  // finds it (a point solves F = 0 whatever F_p is: the two differ only in rounding, 1e-12).
  auto ns_depth = [](const char* from) -> double {
    const CliResult r = run({"continue", "--json", "--set", "model=milling", "--set", "continue_key=depth", "--set",
                             std::string("continue_from=") + from, "--set", "continue_to=0.001"});
    EXPECT_EQ(r.status, 0) << from << ": " << r.err;
    if (r.status != 0) return NAN;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    for (const auto& b : j.at("bifurcations"))
      if (b.at("type") == "neimark-sacker") return b.at("parameter").get<double>();
    return NAN;
  };
  const double from_zero = ns_depth("0"), from_inside = ns_depth("1e-5");
  ASSERT_TRUE(std::isfinite(from_zero) && std::isfinite(from_inside));
  EXPECT_NEAR(from_zero, from_inside, 1e-12 * from_inside);
}

// x' = a x + 0.5 x(t - 1) for a in [1e20, 1e21] and up to 1e308: the exact leading multiplier is
// e^a (no bifurcation: a real root > 0 throughout), while the step cannot resolve h a beyond
// 4 / eps (the trapezoid's factor rounds to -1) and every computed multiplier is 1 to rounding.
// Five "folds" at 1e20 .. 1e21 and four near 1e308 were printed at exit 0 (issue 61 item 9): a
// multiplier within rounding of the circle is not counted outside, so none is.
TEST(ContinueCli, MultipliersOnTheCircleToRoundingAreNoBifurcation) {
  for (const auto& [from, to] : {std::pair{"1e20", "1e21"}, std::pair{"-1", "1e308"}}) {
    const CliResult r = run({"continue", "--json", "--set", "model=linear", "--set", "b=0.5", "--set",
                             "continue_key=a", "--set", std::string("continue_from=") + from, "--set",
                             std::string("continue_to=") + to});
    ASSERT_EQ(r.status, 0) << from << ": " << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_TRUE(j.at("bifurcations").empty()) << from << ": " << j.at("bifurcations").dump();
  }
}

}  // namespace

// Issue 60 item 5: `continue` with period_guess follows the orbit of unknown period from where
// `floquet` finds it (before, issue 61 item 5 refused it: it had followed the map's fixed point,
// the equilibrium, with exit 0). Mackey-Glass from tau = 6 (period ~20) to 14 at N = 100, 200, 400:
//  * the first point is floquet's orbit at tau = 6, N = 400 (the same discrete problem: its period
//    to the Newton tolerances, 1e-9 relative);
//  * the period doubling is found at every N and extrapolated with a bar (measured: 13.249212 +-
//    1.8e-4, order 1.98); checked outside the continuation: `floquet` at N = 1600 (a finer,
//    independent discretisation: the orbit's own K) has its multiplier through -1 between the
//    extrapolated location minus and plus its bar (|mu_1| < 1 below, > 1 above);
//  * continue_switch (the period-2 branch) and a linear model are refused, naming why.
TEST(ContinueCli, AnOrbitOfUnknownPeriodIsFollowedFromWhereFloquetFindsIt) {
  const CliResult r = run({"continue", "--json", "--set", "model=mackey-glass", "--set", "tau=6", "--set",
                           "period_guess=20", "--set", "continue_key=tau", "--set", "continue_from=6", "--set",
                           "continue_to=14", "--set", "continue_Ns=100,200,400"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("fixed point of the stroboscopic map"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["period_guess"], 20);
  const auto floquet_at = [](const std::string& tau, const std::string& period_guess, int N) {
    const CliResult f = run({"floquet", "--json", "--set", "model=mackey-glass", "--set", "tau=" + tau, "--set",
                             "period_guess=" + period_guess, "--set", "N=" + std::to_string(N), "--set", "nev=3",
                             "--set", "error_bars=off"});
    EXPECT_EQ(f.status, 0) << f.err;
    return nlohmann::json::parse(f.out);
  };
  const auto start = floquet_at("6", "20", 400);
  EXPECT_NEAR(j["points"][0]["period"].get<double>(), start["period"].get<double>(),
              1e-9 * start["period"].get<double>());
  ASSERT_EQ(j["bifurcations"].size(), 1u);
  const auto& pd = j["bifurcations"][0];
  EXPECT_EQ(pd["type"], "period-doubling");
  ASSERT_EQ(pd["by_N"].size(), 3u);
  const double at = pd["extrapolated"].get<double>(), bar = pd["error_estimate"].get<double>();
  EXPECT_LT(bar, 1e-3);
  const double below = floquet_at(delayspec::format_number(at - bar), "39.2", 1600)["multipliers"][0]["abs"];
  const double above = floquet_at(delayspec::format_number(at + bar), "39.2", 1600)["multipliers"][0]["abs"];
  EXPECT_LT(below, 1);
  EXPECT_GT(above, 1);

  for (const auto& [extra, says] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"continue_switch=true"}, "`continue_switch = true` with `period_guess`"},
           {{"model=linear", "continue_key=b", "continue_from=-1", "continue_to=-2"}, "a linear model has no isolated"}}) {
    std::vector<std::string> args = {"continue", "--set", "model=mackey-glass", "--set", "period_guess=20", "--set",
                                     "continue_key=tau", "--set", "continue_from=6", "--set", "continue_to=7"};
    for (const std::string& e : extra) args.insert(args.end(), {"--set", e});
    const CliResult bad = run(args);
    EXPECT_EQ(bad.status, 2) << says << ": " << bad.err;
    EXPECT_NE(bad.err.find(says), std::string::npos) << bad.err;
  }
}

// Issue 61 item 7: without period_guess, continuing an autonomous model says what it follows.
TEST(ContinueCli, AnAutonomousModelSaysWhatIsFollowed) {
  const CliResult r = run({"continue", "--set", "model=mackey-glass", "--set", "continue_key=beta", "--set",
                           "continue_from=0.2", "--set", "continue_to=0.21", "--set", "continue_step=0.005"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("model `mackey-glass` is autonomous: this follows the fixed point of the stroboscopic map"),
            std::string::npos)
      << r.err;
}
