// The `delayspec converge` command: JSON keys of the CLI contract, the observed order on the
// smooth models (second order, the trapezoidal rule), the gain of the two-level extrapolation,
// impact events side by side, CSV output, and every bad-input path (exit 2 naming key and value).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_support.hpp"
#include "delayspec/richardson.hpp"
#include "delayspec_test_paths.hpp"

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::run;

}  // namespace

TEST(ConvergeCli, LinearAgainstLambertWIsSecondOrder) {
  // x' = -x + 0.5 x(t - 1): a real leading root; trapezoid error C h^2 (1 + O(h^2)): order 2 to < 0.1.
  CliResult r = run({"converge", "--json", "--set", "model=linear", "--set", "a=-1", "--set", "b=0.5", "--set",
                     "Ns=25,50,100,200", "--set", "nev=3"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"rows", "reference", "observed_order", "extrapolated"}) EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["reference"], "exact");
  ASSERT_EQ(j["rows"].size(), 4u);
  for (const auto& row : j["rows"])
    for (const char* key : {"N", "multipliers", "error", "seconds", "operator_applications", "correct_digits"})
      EXPECT_TRUE(row.contains(key)) << key;
  ASSERT_TRUE(j["observed_order"].is_number()) << j["order_note"];
  EXPECT_GE(j["observed_order"].get<double>(), 1.9);
  EXPECT_LE(j["observed_order"].get<double>(), 2.1);
  EXPECT_EQ(j["extrapolated"].size(), 3u);
  for (const auto& e : j["extrapolated"]) EXPECT_TRUE(e.contains("error_estimate"));
  // Two-level Richardson (column "levels": 2) is O(h^4) against the exact value: >= 3.5.
  ASSERT_TRUE(j["richardson"][1]["observed_order"].is_number());
  EXPECT_GE(j["richardson"][1]["observed_order"].get<double>(), 3.5);
  // A smooth problem keeps every column that shows its order and the first one too short to
  // check (the three-level column, two entries: used, not built upon), and the claimed error
  // bounds the actual error against Lambert W for every track.
  for (size_t k = 0; k < 3; ++k) {
    const auto& e = j["extrapolated"][k];
    const auto& x = j["reference_values"][k];
    EXPECT_EQ(e["levels"], 3) << k << ": " << e["note"];
    const double actual =
        std::hypot(e["re"].get<double>() - x["re"].get<double>(), e["im"].get<double>() - x["im"].get<double>());
    EXPECT_LE(actual, e["error_estimate"].get<double>()) << k;
  }
}

TEST(ConvergeCli, MathieuIsSecondOrderAndTwoLevelExtrapolationGains) {
  // Issue 6 target parameters; no exact value, so orders come from successive differences and the
  // Richardson columns are measured against the 4-level extrapolation (O(h^8), ~1e-10 here).
  CliResult r = run({"converge", "--json", "--set", "model=mathieu", "--set", "kappa=0.1", "--set", "delta=1", "--set",
                     "eps=1", "--set", "b=0.2", "--set", "N_min=25", "--set", "N_max=400", "--set",
                     "reference=extrapolated"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["reference"], "extrapolated");
  EXPECT_EQ(j["rows"].size(), 5u);  // 25, 50, 100, 200, 400
  ASSERT_TRUE(j["observed_order"].is_number()) << j["order_note"];
  EXPECT_GE(j["observed_order"].get<double>(), 1.9);
  EXPECT_LE(j["observed_order"].get<double>(), 2.1);
  ASSERT_TRUE(j["richardson"][1]["observed_order"].is_number());
  EXPECT_GE(j["richardson"][1]["observed_order"].get<double>(), 3.5);
  // The published |mu_1| = 1.267945049893 (12 digits): the extrapolation reaches it to 1e-10.
  EXPECT_NEAR(j["extrapolated"][0]["abs"].get<double>(), 1.267945049893, 1.3e-10);
  // Smooth: every column is used (the three checkable ones show orders 2, 4, 6), so the digits
  // stay; the claimed error bounds the distance to the published value (plus its rounding, 5e-13).
  EXPECT_EQ(j["extrapolated"][0]["levels"], 4) << j["extrapolated"][0]["note"];
  for (int c = 0; c < 3; ++c) EXPECT_EQ(j["richardson"][c]["consistent"], true) << c;
  EXPECT_LE(std::abs(j["extrapolated"][0]["abs"].get<double>() - 1.267945049893),
            j["extrapolated"][0]["error_estimate"].get<double>() + 5e-13);
}

namespace {

// mu_1 (upper half plane) of every row, and the extrapolation of the CLI's JSON.
std::vector<std::complex<double>> upper_track(const nlohmann::json& j) {
  std::vector<std::complex<double>> z;
  for (const auto& row : j["rows"]) {
    std::complex<double> m(row["multipliers"][0]["re"].get<double>(), row["multipliers"][0]["im"].get<double>());
    z.push_back(m.imag() < 0 ? std::conj(m) : m);
  }
  return z;
}

std::complex<double> upper(const nlohmann::json& e) { return {e["re"].get<double>(), std::abs(e["im"].get<double>())}; }

}  // namespace

// Events: a split trapezoid step has a clean h^2 term and then non-smooth terms (docs/events.md),
// so only the first elimination is justified. Paper orbit at k = 0 (a forced 2-d ODE) against an
// independent reference: mu_1 = -0.7716866934 + 0.5093824592i from scripts/floquet_results.py
// k0-reference (RK4 + bisection, stable to 2e-9; no delayspec code). N = 400 ... 3200, Newton
// orbits. Measured: the old 4-level extrapolation claimed 3.6e-6 for an error of 7.0e-5 (20x
// optimistic); the checked one uses 2 levels (column 2 shows order 2.1, expected 4), errs by
// 5.1e-5 and claims 2.6e-4.
TEST(ConvergeCli, ImpactWithEventsClaimsAnErrorThatBoundsTheIndependentReference) {
  CliResult r = run({"converge", std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/default.toml", "--json", "--set",
                     "k=0", "--set", "orbit=newton", "--set", "orbit_guess_periods=30", "--set", "Ns=400,800,1600,3200",
                     "--set", "nev=2", "--set", "events=on", "--set", "grid=uniform"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  const std::complex<double> reference(-0.7716866934, 0.5093824592);
  const auto& e = j["extrapolated"][0];
  ASSERT_TRUE(e["error_estimate"].is_number()) << e["note"];
  // the reference's own uncertainty, 2e-9, is far below anything compared here
  EXPECT_LE(std::abs(upper(e) - reference), e["error_estimate"].get<double>()) << e["note"];
  EXPECT_LT(e["levels"].get<int>(), 4) << e["note"];
  EXPECT_EQ(j["richardson"][1]["consistent"], false);
  // The claim is still useful: better than the finest level's own error (1.3e-3).
  EXPECT_LT(e["error_estimate"].get<double>(), std::abs(upper_track(j).back() - reference));
  // The old behaviour (all columns, orders not checked) on the same levels claims less than its
  // actual error: what this test guards against.
  std::vector<double> h;
  for (const auto& row : j["rows"]) h.push_back(1.0 / row["N"].get<int>());
  const delayspec::Extrapolation old = delayspec::richardson_extrapolate(h, upper_track(j), {.check_orders = false});
  EXPECT_EQ(old.levels, 4);
  EXPECT_GT(std::abs(old.value - reference), 5 * old.error_estimate);
}

// The same at the paper's k = 0.2 (default scene, simulated orbits, N = 100 ... 3200: the case of
// docs/benchmarks.md). Reference: Richardson of N = 12800 and 25600 (Newton orbits,
// `delayspec floquet data/scenes/default.toml --set N=... --set orbit=newton --set
// orbit_guess_periods=30`): 0.09681535694766724 + 0.6142427096911214i; not independent of the
// stepper, but of everything under test here; its own error is below its last correction,
// 9.3e-6 (k = 0 analogue: 1.0e-6 against the ODE reference, docs/events.md). Measured: old
// claim 1.8e-6 for an error of 3.1e-5; checked: 2 levels, error 2.4e-5, claim 1.0e-4.
TEST(ConvergeCli, ImpactDefaultSceneClaimsAnErrorThatBoundsTheFineReference) {
  CliResult r = run({"converge", std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/default.toml", "--json", "--set",
                     "Ns=100,200,400,800,1600,3200", "--set", "nev=2", "--set", "events=on", "--set", "grid=uniform"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  const std::complex<double> reference(0.09681535694766724, 0.6142427096911214);
  const double reference_error = 9.3e-6;
  const auto& e = j["extrapolated"][0];
  ASSERT_TRUE(e["error_estimate"].is_number()) << e["note"];
  EXPECT_LE(std::abs(upper(e) - reference) + reference_error, e["error_estimate"].get<double>()) << e["note"];
  std::vector<double> h;
  for (const auto& row : j["rows"]) h.push_back(1.0 / row["N"].get<int>());
  const delayspec::Extrapolation old = delayspec::richardson_extrapolate(h, upper_track(j), {.check_orders = false});
  EXPECT_GT(std::abs(old.value - reference) - reference_error, old.error_estimate);
}

// ---------------- Round-off-level studies: a finite estimate that bounds the truth ----------------

// Linear DDEs against Lambert W (exact, to ~1e-15: lambert_w.hpp), nev = 6, at several Ns lists:
// coarse lists where truncation dominates, and 50 .. 800 / 200 .. 1600 where the extrapolation
// reaches round-off (before issue 13: error_estimate null for mu_1 at 50 .. 800, and estimates
// below the actual error, 2.5e-15 claimed 1.3e-15, for the third multiplier). Every claim must
// bound the actual error; at round-off it must be finite and still useful (< 1e-10 |mu_1|: the
// floor is absolute, set by the operator's norm, so small multipliers get a larger relative one).
TEST(ConvergeCli, LinearStudiesClaimAFiniteErrorThatBoundsLambertW) {
  const std::vector<std::vector<std::string>> cases{{"a=-1", "b=-2", "tau=1", "period=2"},
                                                    {"a=-1", "b=0.5", "tau=1", "period=1"},
                                                    {"a=0.2", "b=-1", "tau=1", "period=3"}};
  for (const auto& params : cases)
    for (const std::string ns :
         {"25,50,100", "100,200,400", "25,50,100,200", "50,100,200,400,800", "200,400,800,1600"}) {
      std::vector<std::string> args{"converge", "--json",   "--set", "model=linear",
                                    "--set",    "Ns=" + ns, "--set", "nev=6"};
      for (const auto& p : params) args.insert(args.end(), {"--set", p});
      CliResult r = run(args);
      ASSERT_EQ(r.status, 0) << r.err;
      auto j = nlohmann::json::parse(r.out);
      ASSERT_EQ(j["reference"], "exact");
      for (size_t k = 0; k < 6; ++k) {
        const auto& e = j["extrapolated"][k];
        const auto& x = j["reference_values"][k];
        const std::string where =
            params[0] + " " + params[1] + " " + params[3] + " Ns=" + ns + " track " + std::to_string(k);
        ASSERT_TRUE(e["error_estimate"].is_number()) << where << ": " << e["note"];
        const double actual =
            std::hypot(e["re"].get<double>() - x["re"].get<double>(), e["im"].get<double>() - x["im"].get<double>());
        EXPECT_LE(actual, e["error_estimate"].get<double>()) << where << ": " << e["note"];
        if (ns == "50,100,200,400,800" || ns == "200,400,800,1600") {
          EXPECT_LT(e["error_estimate"].get<double>(), 1e-10 * j["reference_values"][0]["abs"].get<double>()) << where;
        }
      }
    }
}

// The PWSDDE period-2 orbit with three levels (order "not settled": one pair of levels). Before
// issue 13 the claim was 1.7e-6 / 2.7e-7 for errors of 6.1e-6 / 3.4e-6. Reference: the same
// command with Ns = 100,200,400,800,1600,3200,6400 (measured on this code, 7 levels):
// 0.327612853329794 (its estimate 7.4e-8) and 0.15342159164245137 (6.7e-8); both real.
TEST(ConvergeCli, PwsddeThreeLevelsClaimNoLessThanTheFineReference) {
  CliResult r = run({"converge", std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/pwsdde-period2.toml", "--json",
                     "--set", "Ns=100,200,400", "--set", "nev=2"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  const double reference[2] = {0.327612853329794, 0.15342159164245137};
  const double reference_error[2] = {7.4e-8, 6.7e-8};
  for (int k = 0; k < 2; ++k) {
    const auto& e = j["extrapolated"][k];
    ASSERT_TRUE(e["error_estimate"].is_number()) << e["note"];  // withholding would also be honest; this code widens
    const double actual = std::hypot(e["re"].get<double>() - reference[k], e["im"].get<double>());
    EXPECT_LE(actual + reference_error[k], e["error_estimate"].get<double>()) << k << ": " << e["note"];
  }
}

// ---------------- converge_target ----------------

// The delayed Mathieu case kappa 0.1, delta 3, eps 1, b -0.5 from the default Ns = 25 .. 400
// (estimate ~4e-5 there): with converge_target = 1e-10 N doubles until the estimate of both
// tracked multipliers meets it (N = 3200 here, cheap: 5 ms a level). The claim is checked
// against a finer study (Ns = 200 .. 6400, its own estimate added): not independent of the
// stepper, but of the stopping rule under test.
TEST(ConvergeCli, TargetKeepsDoublingNUntilTheEstimateMeetsIt) {
  const std::vector<std::string> mathieu{"converge", "--json",  "--set", "model=mathieu", "--set", "kappa=0.1",
                                         "--set",    "delta=3", "--set", "eps=1",         "--set", "b=-0.5"};
  std::vector<std::string> args = mathieu;
  args.insert(args.end(), {"--set", "converge_target=1e-10"});
  CliResult r = run(args);
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["target_met"], true) << j["stop_note"];
  EXPECT_EQ(j["stopped_by"], "target");
  EXPECT_GT(j["rows"].back()["N"].get<int>(), 400);
  args = mathieu;
  args.insert(args.end(), {"--set", "Ns=200,400,800,1600,3200,6400"});
  CliResult fine = run(args);
  ASSERT_EQ(fine.status, 0) << fine.err;
  auto f = nlohmann::json::parse(fine.out);
  for (int k = 0; k < 2; ++k) {
    const auto& e = j["extrapolated"][k];
    const double estimate = e["error_estimate"].get<double>();
    EXPECT_LE(estimate, 1e-10 * e["abs"].get<double>()) << k;
    const auto& g = f["extrapolated"][k];
    const double distance =
        std::hypot(e["re"].get<double>() - g["re"].get<double>(), e["im"].get<double>() - g["im"].get<double>());
    EXPECT_LE(distance, estimate + g["error_estimate"].get<double>()) << k;
  }
}

TEST(ConvergeCli, TargetStopsAtItsLimitsAndSaysWhich) {
  CliResult r = run({"converge", "--json", "--set", "model=mathieu", "--set", "kappa=0.1", "--set", "delta=3", "--set",
                     "eps=1", "--set", "b=-0.5", "--set", "converge_target=1e-10", "--set", "converge_max_N=800"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["target_met"], false);
  EXPECT_EQ(j["stopped_by"], "converge_max_N");
  EXPECT_EQ(j["rows"].back()["N"], 800);
  EXPECT_NE(j["stop_note"].get<std::string>().find("converge_max_N = 800"), std::string::npos) << j["stop_note"];
  r = run(
      {"converge", "--set", "model=mathieu", "--set", "converge_target=1e-10", "--set", "converge_max_seconds=1e-9"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("stopped: converge_max_seconds = 1e-09"), std::string::npos) << r.out;
  // without a target the JSON says so
  r = run({"converge", "--json", "--set", "model=mathieu", "--set", "Ns=25,50,100"});
  ASSERT_EQ(r.status, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["target_met"].is_null());
  EXPECT_EQ(j["stopped_by"], "Ns");
}

// ---------------- Levels that fail ----------------

namespace {

// orbit = simulate: these tests are about a level whose simulated orbit fails (the default,
// orbit = auto, finds the N = 100 orbit by Newton directly: AutoOrbitFindsTheLevelDirectly).
const std::vector<std::string> kImpactK1{"converge", "--json",    "--set",          "tau_over_T=1",  "--set",
                                         "k=1.0",    "--set",     "Ns=100,200,400", "--set",         "nev=2",
                                         "--set",    "events=on", "--set",          "orbit=simulate"};

std::vector<std::string> with(std::vector<std::string> args, std::initializer_list<std::string> more) {
  args.insert(args.end(), more);
  return args;
}

}  // namespace

// Issue 13: `converge --set tau_over_T=1 --set k=1.0 --set Ns=100,...,3200 --set nev=2` exited 3:
// at N = 100 the orbit is spuriously unstable (|mu_1| = 1.02), so simulation cannot settle. The
// level is retried with Newton from the N = 200 orbit; its multipliers must be those of the
// N = 100 orbit found independently (`floquet --set orbit=newton`: Newton from a simulated guess).
TEST(ConvergeCli, LevelWhoseSimulatedOrbitFailsIsRetriedWithNewtonFromItsNeighbour) {
  CliResult r = run(kImpactK1);
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["rows"].size(), 3u);
  const auto& row = j["rows"][0];
  EXPECT_EQ(row["N"], 100);
  EXPECT_FALSE(row.contains("failure")) << row["failure"];
  ASSERT_TRUE(row.contains("note"));
  EXPECT_NE(row["note"].get<std::string>().find("Newton from the orbit of N = 200"), std::string::npos) << row["note"];
  EXPECT_NE(row["note"].get<std::string>().find("not settled"), std::string::npos) << row["note"];
  ASSERT_EQ(row["multipliers"].size(), 2u);
  CliResult f = run({"floquet", "--json", "--set", "tau_over_T=1", "--set", "k=1.0", "--set", "N=100", "--set", "nev=2",
                     "--set", "orbit=newton"});
  ASSERT_EQ(f.status, 0) << f.err;
  auto fj = nlohmann::json::parse(f.out);
  const double mu = fj["multipliers"][0]["abs"].get<double>();
  EXPECT_GT(mu, 1.0);  // the spurious instability that defeats simulation
  // same orbit (Newton tolerance 1e-12) and same solver: agreement to 1e-9 leaves room for both
  EXPECT_NEAR(row["multipliers"][0]["abs"].get<double>(), mu, 1e-9);
}

// The issue-13 study with the default orbit = auto: the N = 100 level's (spuriously unstable)
// orbit is found directly by Newton, no retry needed, and equals the one the retry finds.
TEST(ConvergeCli, AutoOrbitFindsTheLevelDirectly) {
  std::vector<std::string> args = kImpactK1;
  args.resize(args.size() - 2);  // drop orbit=simulate
  CliResult automatic = run(args);
  ASSERT_EQ(automatic.status, 0) << automatic.err;
  const auto a = nlohmann::json::parse(automatic.out);
  EXPECT_FALSE(a["rows"][0].contains("note")) << a["rows"][0]["note"];
  CliResult retried = run(kImpactK1);
  ASSERT_EQ(retried.status, 0) << retried.err;
  const auto r = nlohmann::json::parse(retried.out);
  // two Newton solutions of one discrete problem (tolerance 1e-12): 1e-9 for the multipliers
  EXPECT_NEAR(a["rows"][0]["multipliers"][0]["abs"].get<double>(), r["rows"][0]["multipliers"][0]["abs"].get<double>(),
              1e-9);
}

// A level that fails everywhere (here Newton is allowed one iteration, too few from the
// prolonged guess) is a row with its reason, `multipliers` [] and `error` null; the study goes on
// with the other levels and exits 0. With no level left it exits 3 naming each failure.
TEST(ConvergeCli, LevelThatFailsEverywhereIsReportedAndTheStudyGoesOn) {
  CliResult r = run(with(kImpactK1, {"--set", "Ns=100,200,400,800", "--set", "orbit_max_iterations=1"}));
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["rows"].size(), 4u);
  const auto& row = j["rows"][0];
  EXPECT_EQ(row["N"], 100);
  ASSERT_TRUE(row.contains("failure"));
  EXPECT_NE(row["failure"].get<std::string>().find("not settled"), std::string::npos) << row["failure"];
  EXPECT_NE(row["failure"].get<std::string>().find("retried from N = 200"), std::string::npos) << row["failure"];
  for (const char* key : {"N", "multipliers", "error", "seconds"}) EXPECT_TRUE(row.contains(key)) << key;
  EXPECT_TRUE(row["multipliers"].empty());
  EXPECT_TRUE(row["error"].is_null());
  for (size_t i = 1; i < 4; ++i) EXPECT_EQ(j["rows"][i]["multipliers"].size(), 2u) << i;
  EXPECT_EQ(j["richardson"][0]["entries"].size(), 3u);  // 200, 400, 800
  // text output names the failed level
  r = run({"converge", "--set", "tau_over_T=1", "--set", "k=1.0", "--set", "Ns=100,200,400", "--set", "nev=2", "--set",
           "events=on", "--set", "orbit=simulate", "--set", "orbit_max_iterations=1"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("failed: orbit by simulation"), std::string::npos) << r.out;
  // nothing left: exit 3, each level named
  r = run(with(kImpactK1, {"--set", "Ns=100,200", "--set", "orbit_max_periods=3"}));
  EXPECT_EQ(r.status, 3) << r.out;
  EXPECT_NE(r.err.find("N = 100: orbit by simulation"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("N = 200: orbit by simulation"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(ConvergeCli, ImpactShowsEventsOnAndOffSideBySideAndWritesCsv) {
  const auto dir = delayspec::testing::fresh_dir("converge_out");
  CliResult r = run({"converge", std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/default.toml", "--json", "--out",
                     dir.string(), "--set", "Ns=100,200,400", "--set", "nev=2"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.contains("by_events"));
  ASSERT_EQ(j["by_events"].size(), 2u);
  EXPECT_EQ(j["by_events"][0]["events"], "on");
  EXPECT_EQ(j["by_events"][1]["events"], "off");
  EXPECT_EQ(j["rows"], j["by_events"][0]["rows"]);  // the contract's top level is the first variant
  // The note is never empty when no order is given: the output says why.
  for (const auto& v : j["by_events"]) {
    if (v["observed_order"].is_null()) {
      EXPECT_FALSE(v["order_note"].get<std::string>().empty());
    }
  }
  std::ifstream csv(dir / "converge.csv");
  ASSERT_TRUE(csv.good());
  std::string line;
  int lines = 0;
  while (std::getline(csv, line))
    if (line.rfind("#", 0) != 0) ++lines;  // the metadata comment lines first (docs/formats.md)
  EXPECT_EQ(lines, 1 + 2 * 3 * 2);         // header, 2 events x 3 N x 2 tracks
  EXPECT_TRUE(std::filesystem::exists(dir / "converge_richardson.csv"));
  std::filesystem::remove_all(dir);
}

TEST(ConvergeCli, TextOutputSaysWhenOrdersAreNotSettled) {
  CliResult r = run({"converge", std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/default.toml", "--set",
                     "Ns=50,100,200,400", "--set", "nev=2", "--set", "events=off"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("observed order"), std::string::npos) << r.out;
  // At these N the impact orbit's multiplier is far from asymptotic (design 1.5): the command must
  // say so rather than print a single order.
  EXPECT_NE(r.out.find("pre-asymptotic"), std::string::npos) << r.out;
}

namespace {

struct ConvergeBadValue {
  const char* key;
  const char* value;
};
void PrintTo(const ConvergeBadValue& b, std::ostream* os) { *os << b.key << "=" << b.value; }
class ConvergeBadInput : public ::testing::TestWithParam<ConvergeBadValue> {};

}  // namespace

TEST_P(ConvergeBadInput, ExitsTwoNamingKeyAndValue) {
  const ConvergeBadValue b = GetParam();
  CliResult r = run({"converge", "--set", "model=mathieu", "--set", std::string(b.key) + "=" + b.value});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(std::string("`") + b.key), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(b.value), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

// clang-format off
INSTANTIATE_TEST_SUITE_P(Keys, ConvergeBadInput, ::testing::Values(
    ConvergeBadValue{"Ns", "50,25"}, ConvergeBadValue{"Ns", "0,10"}, ConvergeBadValue{"Ns", "ten"}, ConvergeBadValue{"Ns", "10,,20"},
    ConvergeBadValue{"N_min", "0"}, ConvergeBadValue{"N_max", "-3"}, ConvergeBadValue{"nev", "0"}, ConvergeBadValue{"nev", "5000"},
    ConvergeBadValue{"reference", "best"}, ConvergeBadValue{"events", "on,maybe"},
    ConvergeBadValue{"events", "on,on"}, ConvergeBadValue{"solver", "magic"}, ConvergeBadValue{"extrapolation_order", "-1"},
    ConvergeBadValue{"extrapolation_order_step", "nan"}, ConvergeBadValue{"extrapolation_levels", "0"},
    // 2^32 + 1 and 2^32 + 400: each would wrap to a valid int (1, 400) if cast before the range check
    ConvergeBadValue{"extrapolation_levels", "4294967297"}, ConvergeBadValue{"N_max", "4294967696"},
    ConvergeBadValue{"converge_target", "-1e-8"}, ConvergeBadValue{"converge_target", "2"}, ConvergeBadValue{"converge_target", "0"},
    ConvergeBadValue{"converge_max_N", "5000"} /* no target */, ConvergeBadValue{"converge_max_seconds", "30"} /* no target */));
// clang-format on

TEST(ConvergeCli, AnExactReferenceWhereThereIsNoneIsBadInput) {
  // The impact orbit's multipliers have no closed form and no spectral reference in the engine
  // (scripts/impact_exact_multipliers.py is outside it): `reference = exact` is refused, naming it.
  CliResult r = run({"converge", "--set", "model=impact", "--set", "reference=exact"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("`reference = exact`"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(ConvergeCli, TargetLimitsOutOfRangeAreBadInput) {
  for (const std::string bad : {"converge_max_N=0", "converge_max_N=20000000", "converge_max_N=100" /* < 400 */,
                                "converge_max_seconds=0", "converge_max_seconds=inf", "converge_max_seconds=-5"}) {
    CliResult r = run({"converge", "--set", "model=mathieu", "--set", "converge_target=1e-8", "--set", bad});
    EXPECT_EQ(r.status, 2) << bad << ": " << r.err;
    const std::string key = bad.substr(0, bad.find('='));
    EXPECT_NE(r.err.find("`" + key), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(bad.substr(bad.find('=') + 1)), std::string::npos) << r.err;
  }
}

TEST(ConvergeCli, ListAndRangeTogetherIsBadInput) {
  CliResult r = run({"converge", "--set", "model=linear", "--set", "Ns=10,20", "--set", "N_max=40"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("`Ns`"), std::string::npos) << r.err;
  r = run({"converge", "--set", "model=linear", "--set", "Ns=10", "--set", "reference=finest"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("finest"), std::string::npos) << r.err;
}

TEST(ConvergeCli, DefaultLevelsAreValidGridsWhenTheDelayIsSeveralPeriods) {
  // tau/T = 2 needs even N and tau/T = 4 multiples of 4 (grid.hpp): the defaults 25, 50, ... were
  // refused ("`N = 25`"). They now start at the first valid N and double as often; the study
  // is second order against Lambert W as on any other grid.
  for (const char* period : {"0.5", "0.25"}) {
    const CliResult r = run({"converge", "--json", "--set", "model=linear", "--set", "a=0", "--set", "b=-0.3",
                             "--set", "tau=1", "--set", std::string("period=") + period, "--set", "nev=4"});
    ASSERT_EQ(r.status, 0) << period << ": " << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j.at("rows").size(), 5u);
    EXPECT_EQ(j.at("rows")[0].at("N"), std::string(period) == "0.5" ? 26 : 28);
    for (size_t i = 1; i < 5; ++i) EXPECT_EQ(j.at("rows")[i].at("N"), 2 * j.at("rows")[i - 1].at("N").get<int>());
    EXPECT_NEAR(j.at("observed_order").get<double>(), 2.0, 0.1) << j.at("observed_order");
  }
  // Given explicitly, an invalid range is still the user's to fix.
  const CliResult given = run({"converge", "--set", "model=linear", "--set", "tau=1", "--set", "period=0.5",
                               "--set", "N_min=25", "--set", "N_max=100"});
  EXPECT_EQ(given.status, 2) << given.err;
  EXPECT_NE(given.err.find("`N = 25`"), std::string::npos) << given.err;
}

TEST(ConvergeCli, APlateauRefusesTheEstimateAndTheTarget) {
  // The impact orbit at tau = T, k = 0.55 with events = off: |mu_1| is piecewise constant in N
  // while the set of grid nodes in contact stays the same. Over 200 .. 1600 the last differences
  // are 1.9e-4 and 4.7e-5 while the limit is 1.2e-2 away (0.82558: floquet, events = on); the
  // estimate was 4.7e-4 and `converge_target = 1e-3` reported target_met (issue 32, item 3).
  const CliResult r = run({"converge", "--json", "--set", "tau_over_T=1", "--set", "k=0.55", "--set", "nev=2", "--set",
                           "events=off", "--set", "Ns=200,400,800,1600", "--set", "converge_target=1e-3", "--set",
                           "converge_max_N=1600"});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j.at("extrapolated")[0].at("error_estimate").is_null()) << j.at("extrapolated")[0];
  EXPECT_FALSE(j.at("target_met").get<bool>());
}

// Issue 61 item 10: the deep-contact orbit (tau = T, k = 0.55, e = 1) with events = off. Its
// values over N = 3200 .. 25600 converge like h^2 (differences 1.2e-5, 3.1e-6, 7.7e-7) while the
// first-order term of the contact's place in its step is hidden (richardson.cpp,
// hidden_leading_term): the last differences claimed 3.8e-6 for an actual error of 8.4e-5 and
// the target 1e-3 was "met". The exact |mu_1| = 0.93042800546839921519 (e = 1:
// scripts/impact_exact_multipliers.py --k 0.55 --e 1.0, mpmath, no delayspec code). Now every
// bar printed covers it, and the target is met only by a bar that does.
TEST(ConvergeCli, AHiddenFirstOrderTermWithEventsOffGetsNoShortBar) {
  const double exact = 0.93042800546839921519;
  for (const char* levels : {"Ns=25,50,100,200,400,800,1600,3200,6400,12800,25600", "converge_target=0.001"}) {
    const CliResult r = run({"converge", "--json", "--set", "tau_over_T=1", "--set", "k=0.55", "--set", "e=1.0", "--set",
                             "nev=2", "--set", "events=off", "--set", levels});
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    const auto& e = j.at("extrapolated")[0];
    if (std::string(levels).rfind("Ns", 0) == 0) {
      ASSERT_FALSE(e.at("error_estimate").is_null()) << e;
    }
    if (!e.at("error_estimate").is_null()) {
      EXPECT_LE(std::abs(e.at("abs").get<double>() - exact), e.at("error_estimate").get<double>()) << levels << e;
    }
    if (j.at("target_met").is_boolean() && j.at("target_met").get<bool>()) {
      EXPECT_FALSE(e.at("error_estimate").is_null()) << levels;
    }
  }
}

// Issue 32, item 3: on an impacting orbit the raw order wanders with N (where the contact's ends
// fall in the grid), so the h^4 column never shows its order; the estimate used to be refused
// (null) while the value was excellent. The bar now comes from the spread of the h^2-eliminated
// column (richardson.hpp). Checked against the exact multipliers at tau = T: there the orbit does
// not depend on k (the control vanishes on it) and mu solves det(Phi(mu) - mu I) = 0 with Phi the
// monodromy of y' = (A(t) + B / mu) y along it, solved in 40 digits by
// scripts/impact_exact_multipliers.py (mpmath; no delayspec code): |mu_1| = 0.82557832108367955172
// at k = 0.55 and 0.93825120174378664294 at k = 1. The bar must cover the actual error and be
// worth having: below the finest level's own error.
TEST(ConvergeCli, AnImpactingOrbitGetsAnHonestBarFromTheWanderingSecondOrderColumn) {
  for (const auto& [k, exact] : {std::pair{"0.55", 0.82557832108367955172}, std::pair{"1.0", 0.93825120174378664294}}) {
    const CliResult r = run({"converge", "--json", "--set", "tau_over_T=1", "--set", std::string("k=") + k, "--set",
                             "nev=2", "--set", "events=on", "--set", "Ns=800,1600,3200,6400,12800", "--set",
                             "grid=uniform"});
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    const auto& e = j.at("extrapolated")[0];
    ASSERT_FALSE(e.at("error_estimate").is_null()) << e;
    const double bar = e.at("error_estimate"), error = std::abs(e.at("abs").get<double>() - exact);
    EXPECT_LE(error, bar) << "k = " << k << ": " << e;
    const double finest = std::abs(j.at("rows").back().at("multipliers")[0].at("abs").get<double>() - exact);
    EXPECT_LT(bar, finest) << "k = " << k << ": " << e;
    EXPECT_NE(e.at("note").get<std::string>().find("spread"), std::string::npos) << e.at("note");
  }
}


// Issue 58 item 5: a linear model with one delay tau = T (the delayed Mathieu equation, milling)
// has a reference no step map produced: piecewise Chebyshev collocation (spectral_reference.hpp),
// taken where its own estimate is within 1e-10 (reference "exact", reference_source "spectral").
// The trapezoid's Richardson extrapolation meets it within its bar, and both meet to ~1e-12: two
// discretisations that share only the model's A and B.
TEST(ConvergeCli, LinearPeriodicModelsAreScoredAgainstTheSpectralReference) {
  for (const std::vector<std::string>& model :
       {std::vector<std::string>{"model=mathieu", "delta=1", "eps=1", "b=0.2", "nev=2"},
        std::vector<std::string>{"model=milling", "radial_immersion=0.05", "depth=2e-3", "nev=1"}}) {
    SCOPED_TRACE(model[0]);
    std::vector<std::string> sets = model;
    sets.insert(sets.end(), {"Ns=50,100,200,400,800,1600", "solver=spectra", "tol=1e-14"});
    const CliResult r = run(with_sets({"converge", "--json"}, sets));
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("reference"), "exact");
    EXPECT_EQ(j.at("reference_source"), "spectral");
    const double reference = j.at("reference_values")[0].at("abs");
    const auto& e = j.at("extrapolated")[0];
    ASSERT_TRUE(e.at("error_estimate").is_number()) << e;
    EXPECT_LE(std::abs(e.at("abs").get<double>() - reference), e.at("error_estimate").get<double>()) << e;
    EXPECT_LT(e.at("error_estimate").get<double>(), 1e-10) << e;
  }
}

// Issue 61 item 6: with `Ns` the scene's N is not a level and is not checked against the grid:
// tau / T = 19 / 13 needs N divisible by 19, and an N = 100 beside valid Ns used to be refused.
TEST(ConvergeCli, TheLevelsOfNsAreUsedNotTheScenesN) {
  const CliResult r = run({"converge", "--json", "--set", "model=linear", "--set", "tau=1.9", "--set", "period=1.3",
                           "--set", "N=100", "--set", "Ns=19,38,76", "--set", "nev=1"});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("rows").size(), 3u);
  EXPECT_EQ(j.at("rows")[0].at("N"), 19);
}

// Issue 61 item 9: with events = on,off side by side the top level's target_met is every
// variant's; it said true (the first variant's) while the events = off study missed the target.
TEST(ConvergeCli, TheTopLevelTargetIsMetOnlyWhenEveryEventsVariantMetIt) {
  const CliResult r = run({"converge", "--json", "--set", "tau_over_T=1", "--set", "k=0.55", "--set", "nev=2", "--set",
                           "converge_target=1e-4", "--set", "converge_max_N=800"});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("by_events").size(), 2u);
  const bool on = j["by_events"][0].at("target_met"), off = j["by_events"][1].at("target_met");
  EXPECT_EQ(j.at("target_met").get<bool>(), on && off);
  ASSERT_FALSE(off) << "events = off meets 1e-4 by N = 800: pick a stricter case";
  EXPECT_NE(j.at("target_note").get<std::string>().find("events = off: not met"), std::string::npos) << j["target_note"];
}
