// The `delayspec lyapunov` and `delayspec sweep` commands: contract JSON keys, bad input (exit 2
// naming key and value), files written point by point, --resume completing an interrupted sweep.
#include <gtest/gtest.h>

#include <cmath>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_test_support.hpp"
#include "point_logs.hpp"
#include "delayspec_test_paths.hpp"

namespace {

namespace fs = std::filesystem;

using delayspec::testing::CliResult;
using delayspec::testing::fresh_dir;
using delayspec::testing::read_text;
using delayspec::testing::run;
using delayspec::testing::forget_points;
using delayspec::testing::without_metadata;

struct LyapunovBadValue {
  const char* key;
  const char* value;
};
void PrintTo(const LyapunovBadValue& b, std::ostream* os) { *os << b.key << "=" << b.value; }

class LyapunovBadInput : public ::testing::TestWithParam<LyapunovBadValue> {};
class SweepBadInput : public ::testing::TestWithParam<LyapunovBadValue> {};

const std::vector<std::string> kSmallLinear = {"--set", "model=linear", "--set", "N=10",
                                               "--set", "periods=20",   "--set", "transient=0"};

}  // namespace

TEST_P(LyapunovBadInput, ExitsTwoNamingKeyAndValue) {
  const LyapunovBadValue b = GetParam();
  auto args = kSmallLinear;
  args.insert(args.begin(), "lyapunov");
  args.insert(args.end(), {"--set", std::string(b.key) + "=" + b.value});
  CliResult r = run(args);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(std::string("`") + b.key), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(b.value), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

// clang-format off
INSTANTIATE_TEST_SUITE_P(Keys, LyapunovBadInput, ::testing::Values(
    LyapunovBadValue{"exponents", "0"}, LyapunovBadValue{"exponents", "12"}, LyapunovBadValue{"exponents", "two"},
    LyapunovBadValue{"periods", "1"}, LyapunovBadValue{"periods", "-5"}, LyapunovBadValue{"periods", "1e-3"},
    LyapunovBadValue{"transient", "-1"}, LyapunovBadValue{"transient", "x"}, LyapunovBadValue{"seed", "-3"}, LyapunovBadValue{"seed", "abc"},
    LyapunovBadValue{"qr_every", "0"}, LyapunovBadValue{"qr_every", "3"}, LyapunovBadValue{"batches", "1"}, LyapunovBadValue{"N", "0"},
    // issue 13: upper bounds checked before anything is allocated (exit 2, not 1 from
    // "cannot create std::vector"), and no wrap in a narrowing cast (2^32 + 2 -> 2)
    LyapunovBadValue{"periods", "1000000000000000000"}, LyapunovBadValue{"transient", "2000000000"},
    LyapunovBadValue{"exponents", "4294967298"}, LyapunovBadValue{"periods", "200000000"}, LyapunovBadValue{"contact_substeps", "100000"},
    LyapunovBadValue{"N", "4294967298"}));
// clang-format on

TEST(LyapunovCli, JsonHasContractKeys) {
  CliResult r = run({"lyapunov", "--json", "--set", "model=linear", "--set", "a=-1", "--set", "b=-2", "--set", "N=20",
                     "--set", "periods=40", "--set", "transient=10", "--set", "exponents=3"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);  // exactly one JSON object on stdout
  for (const char* key : {"N", "exponents_per_period", "exponents_per_time", "standard_error_per_period", "periods",
                          "transient", "seconds"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["exponents_per_period"].size(), 3u);
  // the error and its two parts (lyapunov.hpp): error^2 = batch SE^2 + fluctuation bound^2
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(j["standard_error_per_period"][i].get<double>(),
                std::hypot(j["batch_standard_error_per_period"][i].get<double>(),
                           j["fluctuation_bound_per_period"][i].get<double>()),
                1e-15 * j["standard_error_per_period"][i].get<double>())
        << i;
  EXPECT_EQ(j["periods"], 40);
  EXPECT_EQ(j["transient"], 10);
  // period = tau = 1 by default for `linear`: per time equals per period
  for (int i = 0; i < 3; ++i)
    EXPECT_DOUBLE_EQ(j["exponents_per_time"][i].get<double>(), j["exponents_per_period"][i].get<double>());
}

TEST(LyapunovCli, OverflowExitsThree) {
  CliResult r = run({"lyapunov", "--set", "model=linear", "--set", "a=800", "--set", "b=0", "--set", "N=1000", "--set",
                     "periods=4", "--set", "transient=0", "--set", "exponents=1"});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("numerical failure"), std::string::npos) << r.err;
}

// More exponents than the rank of the period map: its image has fewer dimensions than tangent
// vectors, so after one period the last vector is a combination of the others (to rounding) and
// the QR's n eps test must stop the run with exit 3 naming it. x' = -x (b = 0): the map is
// rank 1 (the history is forgotten); impact with k = 0 is an ODE, rank 2 (d = 2).
TEST(LyapunovCli, MoreExponentsThanTheRankOfTheMapExitsThree) {
  const std::vector<std::vector<std::string>> runs = {
      {"--set", "model=linear", "--set", "b=0", "--set", "exponents=2"},
      {"--set", "model=impact", "--set", "k=0", "--set", "exponents=3"}};
  for (const auto& keys : runs) {
    std::vector<std::string> args = {"lyapunov", "--set", "N=20", "--set", "periods=10", "--set", "transient=0"};
    args.insert(args.end(), keys.begin(), keys.end());
    CliResult r = run(args);
    EXPECT_EQ(r.status, 3) << keys[1] << ": " << r.err;
    EXPECT_NE(r.err.find("became linearly dependent"), std::string::npos) << r.err;
  }
}

TEST_P(SweepBadInput, ExitsTwoNamingKeyAndValue) {
  const LyapunovBadValue b = GetParam();
  std::vector<std::string> args = {"sweep", "--set", "sweep_key=b", "--set", "sweep_from=-1", "--set", "sweep_to=1"};
  args.insert(args.end(), kSmallLinear.begin(), kSmallLinear.end());
  args.insert(args.end(), {"--set", std::string(b.key) + "=" + b.value});
  CliResult r = run(args);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(std::string("`") + b.key), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(b.value), std::string::npos) << r.err;
}

// clang-format off
INSTANTIATE_TEST_SUITE_P(Keys, SweepBadInput, ::testing::Values(
    LyapunovBadValue{"sweep_key", "periods"}, LyapunovBadValue{"sweep_key", "model"}, LyapunovBadValue{"sweep_from", "nan"},
    LyapunovBadValue{"sweep_to", "x"}, LyapunovBadValue{"sweep_points", "0"}, LyapunovBadValue{"threads", "-2"},
    LyapunovBadValue{"section_points", "-1"}, LyapunovBadValue{"exponents", "0"}));
// clang-format on

TEST(SweepCli, SweptKeyMustBeAParameterOfTheModel) {
  // `kappa` is a mathieu key, not a linear one: reported as unknown
  CliResult r = run({"sweep", "--set", "model=linear", "--set", "sweep_key=kappa", "--set", "sweep_from=0", "--set",
                     "sweep_to=1", "--set", "N=10", "--set", "periods=20"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("`kappa`"), std::string::npos) << r.err;
  // a value outside the model's domain at some point of the range
  r = run({"sweep", "--set", "model=linear", "--set", "sweep_key=tau", "--set", "sweep_from=1", "--set", "sweep_to=-1",
           "--set", "sweep_points=3", "--set", "N=10", "--set", "periods=20"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("`tau"), std::string::npos) << r.err;
  EXPECT_EQ(run({"sweep", "--set", "sweep_from=0"}).status, 2);  // no sweep_key
}

// A linear sweep over b: at each point the exponents must equal a lyapunov run at that point.
TEST(SweepCli, PointsEqualSingleRunsAndFilesAreComplete) {
  const fs::path dir = fresh_dir("lyapunov_sweep");
  std::vector<std::string> args = {"sweep", "--json",           "--out", dir.string(),  "--set", "sweep_key=b",
                                   "--set", "sweep_from=-2",    "--set", "sweep_to=-1", "--set", "sweep_points=3",
                                   "--set", "section_points=4", "--set", "threads=2"};
  args.insert(args.end(), kSmallLinear.begin(), kSmallLinear.end());
  CliResult r = run(args);
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["points"].size(), 3u);
  CliResult single = run({"lyapunov", "--json", "--set", "model=linear", "--set", "N=10", "--set", "periods=20",
                          "--set", "transient=0", "--set", "b=-1.5"});
  ASSERT_EQ(single.status, 0) << single.err;
  auto s = nlohmann::json::parse(single.out);
  // same arithmetic, different thread: identical to the last bit
  EXPECT_EQ(j["points"][1]["parameter"].get<double>(), -1.5);
  EXPECT_EQ(j["points"][1]["exponents_per_period"], s["exponents_per_period"]);
  EXPECT_EQ(j["points"][1]["section_x"].size(), 4u);
  for (const char* f : {"exponents.csv", "section.csv", "sweep.json", "sweep_settings.json"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  const std::string with_metadata = read_text(dir / "exponents.csv");
  // the metadata header names the swept key, not its per-point value
  EXPECT_NE(with_metadata.find("\n# sweep_key = b\n"), std::string::npos) << with_metadata;
  EXPECT_EQ(with_metadata.find("\n# b = "), std::string::npos) << with_metadata;
  const std::string csv = without_metadata(with_metadata);
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "parameter,lambda1,lambda2,se1,se2,lambda1_per_time,lambda2_per_time,seconds");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4);  // header + 3 points
  const std::string section = without_metadata(read_text(dir / "section.csv"));
  EXPECT_EQ(std::count(section.begin(), section.end(), '\n'), 1 + 3 * 4);
  // the same directory again is refused: it holds a finished sweep (test_cli_output_dir.cpp has
  // the interrupted case, which advises --resume)
  CliResult again = run(args);
  EXPECT_EQ(again.status, 2);
  EXPECT_NE(again.err.find("already holds a finished sweep"), std::string::npos) << again.err;
  fs::remove_all(dir);
}

// An interrupted sweep: two point files and no final files. --resume computes only the missing
// points and produces the same tables as an uninterrupted sweep; other settings are refused.
TEST(SweepCli, ResumeCompletesAnInterruptedSweep) {
  const fs::path dir = fresh_dir("lyapunov_resume");
  std::vector<std::string> args = {"sweep",      "--json",      "--quiet",       "--out",         dir.string(),
                                   "--set",      "sweep_key=a", "--set",         "sweep_from=-2", "--set",
                                   "sweep_to=0", "--set",       "sweep_points=5"};
  args.insert(args.end(), kSmallLinear.begin(), kSmallLinear.end());
  ASSERT_EQ(run(args).status, 0);
  const std::string complete_csv = read_text(dir / "exponents.csv");
  // simulate the interruption after points 0 and 3
  for (const char* f : {"exponents.csv", "section.csv", "sweep.json"}) fs::remove(dir / f);
  forget_points(dir / "points", {1, 2, 4});
  std::vector<std::string> changed = args;
  changed.insert(changed.end(), {"--set", "seed=9", "--resume"});
  CliResult refused = run(changed);
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.err.find("`seed`"), std::string::npos) << refused.err;
  args.push_back("--resume");
  CliResult r = run(args);
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["points_computed_now"], 3);
  // the seconds column and the metadata (wall time) differ between runs; compare everything else
  auto strip_seconds = [](const std::string& csv) {
    std::string out;
    std::stringstream ss(without_metadata(csv));
    std::string line;
    while (std::getline(ss, line))
      if (line.rfind("#", 0) != 0) out += line.substr(0, line.rfind(',')) + "\n";  // (metadata: times differ)
    return out;
  };
  EXPECT_EQ(strip_seconds(read_text(dir / "exponents.csv")), strip_seconds(complete_csv));
  fs::remove_all(dir);
}

TEST(SweepCli, ResumeNeedsAnOutDirectoryWithASweep) {
  std::vector<std::string> args = {"sweep", "--resume",      "--set", "sweep_key=a",
                                   "--set", "sweep_from=-2", "--set", "sweep_to=0"};
  args.insert(args.end(), kSmallLinear.begin(), kSmallLinear.end());
  EXPECT_EQ(run(args).status, 2);
  const fs::path dir = fresh_dir("lyapunov_noresume");
  args.insert(args.end(), {"--out", dir.string()});
  CliResult r = run(args);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("sweep_settings.json"), std::string::npos) << r.err;
}

TEST(LyapunovCli, DefaultSceneWorksWithEveryCommandItCouldMean) {
  // Issue 13: the shipped default.toml (floquet's nev and solver in it) is shared by the
  // commands; its keys of other commands are not errors. On the command line they still are.
  const std::string scene = std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/default.toml";
  CliResult r = run({"lyapunov", scene, "--set", "N=20", "--set", "periods=20", "--set", "transient=0"});
  EXPECT_EQ(r.status, 0) << r.err;
  r = run({"simulate", scene, "--set", "N=20", "--set", "t_end=10"});
  EXPECT_EQ(r.status, 0) << r.err;
  r = run({"bench", scene, "--set", "Ns=20", "--set", "solvers=dense", "--set", "nev=2"});
  EXPECT_EQ(r.status, 0) << r.err;
  r = run({"lyapunov", scene, "--set", "N=20", "--set", "periods=20", "--set", "nev=4"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("`nev` (= 4, from --set) is not read by lyapunov"), std::string::npos) << r.err;
}
