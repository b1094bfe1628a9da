// `delayspec run`: dispatch through the command table, metadata in every file, the whole scene
// validated before any computation, and one test per bad-input path (exit 2, nothing written).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_support.hpp"
#include "delayspec_test_paths.hpp"
#include "scene/commands/commands.hpp"

namespace fs = std::filesystem;

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::contains;
using delayspec::testing::fresh_dir;
using delayspec::testing::run;

std::string scene(const std::string& name, const std::string& text) {
  const fs::path path = fresh_dir("run_" + name + ".toml");
  std::ofstream(path) << text;
  return path.string();
}

const char* kLinearScene =
    "title = \"linear test\"\nanalyses = [\"floquet\"]\nmodel = \"linear\"\na = -1\nb = 0.5\n"
    "N = 40\nsolver = \"dense\"\nnev = 3\n";

}  // namespace

TEST(RunCli, WritesResultWithMetadataAndManifest) {
  const fs::path dir = fresh_dir("run_ok");
  const std::string path = scene("ok", kLinearScene);
  CliResult r = run({"run", path, "--out", dir.string(), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto manifest = nlohmann::json::parse(r.out);  // --json: exactly one object on stdout
  EXPECT_EQ(manifest["analyses"][0]["name"], "floquet");

  std::ifstream in(dir / "floquet.json");
  auto result = nlohmann::json::parse(in);
  const auto& meta = result["metadata"];
  for (const char* key : {"delayspec_version", "command", "scene", "parameters", "N", "events", "jacobian",
                          "wall_seconds", "finished_utc"})
    EXPECT_TRUE(meta.contains(key)) << key;
  EXPECT_EQ(meta["N"], 40);
  EXPECT_EQ(meta["scene"], path);
  EXPECT_EQ(meta["parameters"]["b"], "0.5");

  // The same numbers as the command run on its own (run only dispatches).
  CliResult direct = run({"floquet", path, "--json", "--set", "analyses=floquet", "--set", "title=x"});
  ASSERT_EQ(direct.status, 0) << direct.err;
  auto alone = nlohmann::json::parse(direct.out);
  ASSERT_EQ(alone["multipliers"].size(), result["multipliers"].size());
  for (size_t i = 0; i < alone["multipliers"].size(); ++i)
    EXPECT_EQ(alone["multipliers"][i]["re"], result["multipliers"][i]["re"]);
  EXPECT_TRUE(fs::exists(dir / "run.json"));
}

TEST(RunCli, DefaultSceneRuns) {
  const fs::path dir = fresh_dir("run_default");
  CliResult r =
      run({"run", DELAYSPEC_SOURCE_DIR "/data/scenes/default.toml", "--out", dir.string(), "--set", "N=40", "--quiet"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "floquet.json"));
}

struct RunBadInput {
  const char* name;
  std::vector<std::string> extra;  // appended to: run SCENE --out DIR
  const char* expected;            // part of the message
};

void PrintTo(const RunBadInput& b, std::ostream* os) { *os << b.name; }

class RunCliBadInput : public ::testing::TestWithParam<RunBadInput> {};

TEST_P(RunCliBadInput, ExitsTwoWritesNothing) {
  const RunBadInput b = GetParam();
  const fs::path dir = fresh_dir(std::string("run_") + b.name);
  std::vector<std::string> args = {"run", scene(b.name, kLinearScene), "--out", dir.string()};
  args.insert(args.end(), b.extra.begin(), b.extra.end());
  CliResult r = run(args);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err, b.expected)) << r.err;
  EXPECT_FALSE(fs::exists(dir)) << "validation happens before anything is written";
}

// clang-format off
INSTANTIATE_TEST_SUITE_P(Paths, RunCliBadInput, ::testing::Values(
    RunBadInput{"empty_analyses", {"--set", "analyses="}, "`analyses` is empty"},
    RunBadInput{"typo_analysis", {"--set", "analyses=floqet"}, "unknown analysis `floqet`; did you mean `floquet`?"},
    RunBadInput{"far_analysis", {"--set", "analyses=eigenfaces"}, "unknown analysis `eigenfaces` (available: "},
    RunBadInput{"twice", {"--set", "analyses=floquet,floquet"}, "`floquet` is listed twice"},
    RunBadInput{"recursive", {"--set", "analyses=run"}, "`run` is a command, not an analysis"},
    RunBadInput{"unknown_key", {"--set", "nevv=4"}, "unknown key `nevv` (= 4); did you mean `nev`?"},
    RunBadInput{"bad_value", {"--set", "N=zero"}, "`N = zero`: not an integer"}));
// clang-format on

TEST(RunCli, NeedsOutDir) {
  CliResult r = run({"run", scene("noout", kLinearScene)});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "needs --out DIR")) << r.err;
}

TEST(RunCli, UnwritableOutDirIsBadInput) {
  const fs::path dir = fresh_dir("run_blocked");
  fs::create_directories(dir);
  std::ofstream(dir / "file") << "x";
  CliResult r = run({"run", scene("blocked", kLinearScene), "--out", (dir / "file").string()});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "cannot write")) << r.err;
}

TEST(RunCli, EveryAnalysisCommandIsAcceptedByRun) {
  // Every command but run and plot is an analysis `run` accepts by name (what the analysis then
  // does is its own tests' business): never "unknown analysis".
  for (const std::string name : {"simulate", "lyapunov", "sweep", "converge", "bench"}) {
    ASSERT_TRUE(delayspec::cli::is_command(name) && delayspec::cli::command_spec(name).analysis) << name;
    const fs::path dir = fresh_dir("run_analysis_" + name);
    CliResult r = run({"run", scene("analysis", kLinearScene), "--out", dir.string(), "--set", "analyses=" + name,
                       "--set", "N=8", "--quiet"});
    EXPECT_FALSE(contains(r.err, "unknown analysis")) << name << ": " << r.err;
  }
}

TEST(RunCli, SceneWithoutAnalysesRunsTheCommandItsKeysBelongTo) {
  // A chart scene written for `delayspec chart SCENE` (no `analyses`): run infers chart.
  const fs::path dir = fresh_dir("run_inferred");
  const std::string path = scene("inferred",
                                 "model = \"mathieu\"\nN = 8\nsolver = \"dense\"\nchart_x_points = 2\n"
                                 "chart_y_points = 2\n");
  CliResult r = run({"run", path, "--out", dir.string(), "--quiet"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "chart.json"));
  EXPECT_TRUE(fs::exists(dir / "chart.csv"));
}
