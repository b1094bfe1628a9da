// Self-describing commands (issue 13, items 10-12): `COMMAND --help` lists the keys the command
// reads with their defaults (from the key registry, i.e. from the reads themselves); a key of
// another command or model says so instead of a did-you-mean; result metadata records every
// effective default and the source revision; every CSV starts with the metadata lines; every
// shipped scene is accepted by `run`.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_support.hpp"
#include "scene/commands/commands.hpp"
#include "delayspec/version.hpp"
#include "delayspec_test_paths.hpp"
#include "scene/commands/key_registry.hpp"

namespace fs = std::filesystem;

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::contains;
using delayspec::testing::fresh_dir;
using delayspec::testing::read_text;
using delayspec::testing::run;

}  // namespace

TEST(CommandHelp, ListsTheKeysTheCommandReadsWithDefaults) {
  CliResult r = run({"lyapunov", "--help"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* line : {"periods = 1000", "exponents = 2", "transient = 100", "qr_every = 1", "batches = 20",
                           "model = impact", "N = 100", "Lyapunov: periods averaged"})
    EXPECT_TRUE(contains(r.out, line)) << line << "\n" << r.out;
  EXPECT_FALSE(contains(r.out, "nev =")) << "lyapunov does not read nev\n" << r.out;
  EXPECT_FALSE(contains(r.out, "sweep_key")) << r.out;
}

TEST(CommandHelp, EveryCommandStartsWithWhatItDoes) {
  // Each command of the table, the first line: "delayspec COMMAND ...: <a sentence>." (issue 37
  // item 4), so that a command added without its sentence fails here.
  for (const auto& spec : delayspec::cli::command_table()) {
    const std::string& command = spec.name;
    const CliResult r = run({command, "--help"});
    ASSERT_EQ(r.status, 0) << command << ": " << r.err;
    const std::string first = r.out.substr(0, r.out.find('\n'));
    EXPECT_EQ(first.rfind(std::string("delayspec ") + command + " ", 0), 0u) << first;
    EXPECT_TRUE(contains(first, ": ")) << first;
    EXPECT_EQ(first.back(), '.') << first;
    EXPECT_GT(first.size(), 60u) << "a sentence, not a name: " << first;
  }
  EXPECT_EQ(run({"plot", "--help"}).out.rfind("delayspec plot DIR: ", 0), 0u);
}

TEST(CommandHelp, ModelKeysAreListedPerModel) {
  CliResult r = run({"floquet", "--help"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* line : {"nev = 6", "solver = auto", "tol = 1e-12", " with model = impact:", "zeta = 0.01",
                           " with model = linear:", "a = -1", " with model = mathieu:", "kappa = 0.1",
                           " with model = mackey-glass:", "gamma = 0.1"})
    EXPECT_TRUE(contains(r.out, line)) << line << "\n" << r.out;
}

TEST(CommandHelp, RequiredKeysAndCommandSpecificDefaults) {
  CliResult sweep = run({"sweep", "--help"});
  ASSERT_EQ(sweep.status, 0) << sweep.err;
  EXPECT_TRUE(contains(sweep.out, "sweep_key = (required)")) << sweep.out;
  EXPECT_TRUE(contains(sweep.out, "sweep_points = 11")) << sweep.out;
  CliResult chart = run({"chart", "--help"});
  EXPECT_TRUE(contains(chart.out, "nev = 1 ")) << "chart wants only |mu_1|\n" << chart.out;
  EXPECT_TRUE(contains(chart.out, "N = 200 ")) << chart.out;
  EXPECT_TRUE(contains(chart.out, "error_bars = on ")) << "chart gives verdicts by default\n" << chart.out;
  // converge's events default depends on the model (impact: on and off side by side).
  CliResult converge = run({"converge", "--help"});
  EXPECT_TRUE(contains(converge.out, "events = on (linear, mathieu, mackey-glass); on,off (impact, milling)"))
      << converge.out;
}

TEST(KeyRegistry, EveryKeyReadHasAMeaningAndEveryMeaningIsRead) {
  const auto& readers = delayspec::cli::key_index().readers;
  const auto& meanings = delayspec::cli::key_meanings();
  for (const auto& [key, by] : readers) EXPECT_TRUE(meanings.count(key)) << "no meaning for key `" << key << "`";
  for (const auto& [key, meaning] : meanings) EXPECT_TRUE(readers.count(key)) << "no command reads `" << key << "`";
  EXPECT_GT(readers.size(), 60u);  // the probes reach every command's keys (today 80)
}

TEST(UnreadKey, KeyOfAnotherCommandSaysItIsNotRead) {
  CliResult r = run({"lyapunov", "--set", "nev=4", "--set", "model=linear"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err,
                       "`nev` (= 4, from --set) is not read by lyapunov (it is a key of bench, boundary, chart, continue, "
                       "converge, floquet"))
      << r.err;
  EXPECT_TRUE(contains(r.err, "`delayspec lyapunov --help` lists the keys it reads")) << r.err;
  EXPECT_FALSE(contains(r.err, "did you mean")) << r.err;
}

TEST(UnreadKey, KeyOfAnotherModelNamesTheModel) {
  CliResult r = run({"floquet", "--set", "model=linear", "--set", "kappa=1", "--set", "solver=dense"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err,
                       "`kappa` (= 1, from --set) is not read by floquet with model = linear (only with "
                       "model = mathieu)"))
      << r.err;
}

TEST(UnreadKey, MisspeltKeyStillGetsADidYouMean) {
  CliResult r = run({"lyapunov", "--set", "periodz=10"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "unknown key `periodz` (= 10, from --set); did you mean `periods`?")) << r.err;
  // A known key in the wrong case is still pointed to the right one.
  r = run({"floquet", "--set", "n=40"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "did you mean `N`?")) << r.err;
}

TEST(UnreadKey, RunNamesTheAnalysesOfTheScene) {
  const fs::path dir = fresh_dir("keys_run_unread");
  CliResult r =
      run({"run", DELAYSPEC_SOURCE_DIR "/data/scenes/default.toml", "--out", dir.string(), "--set", "exponents=3"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "`exponents` (= 3) is not read by floquet")) << r.err;
  EXPECT_FALSE(fs::exists(dir));
}

TEST(Metadata, RecordsEffectiveDefaultsAndTheSourceRevision) {
  const fs::path dir = fresh_dir("keys_metadata");
  CliResult r = run({"run", DELAYSPEC_SOURCE_DIR "/data/scenes/default.toml", "--out", dir.string(), "--set", "N=40",
                     "--set", "solver=dense", "--quiet"});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json m = nlohmann::json::parse(read_text(dir / "floquet.json"))["metadata"];
  EXPECT_EQ(m["parameters"]["N"], "40");  // given
  ASSERT_TRUE(m.contains("defaults")) << m.dump(1);
  EXPECT_EQ(m["defaults"]["events"], "on");
  EXPECT_EQ(m["defaults"]["jacobian"], "consistent");
  EXPECT_EQ(m["defaults"]["orbit"], "auto");
  EXPECT_EQ(m["defaults"]["contact_substeps"], "4");
  EXPECT_FALSE(m["defaults"].contains("N")) << "a given key is not a default";
  EXPECT_EQ(m["source_revision"], DELAYSPEC_REVISION);
  // In a git checkout the revision is known (configure time); "unknown" only outside one.
  if (fs::exists(fs::path(DELAYSPEC_SOURCE_DIR) / ".git")) {
    EXPECT_NE(m["source_revision"], "unknown");
  }
}

TEST(Metadata, EveryCsvStartsWithTheMetadataLines) {
  const fs::path dir = fresh_dir("keys_csv");
  const std::string out = dir.string();
  const std::vector<std::vector<std::string>> commands = {
      {"simulate", "--set", "model=linear", "--set", "N=10", "--set", "t_end=4"},
      {"sweep",      "--set",         "model=linear", "--set",          "sweep_key=a", "--set", "sweep_from=-1",
       "--set",      "sweep_to=-0.5", "--set",        "sweep_points=2", "--set",       "N=10",  "--set",
       "periods=20", "--set",         "transient=2",  "--set",          "exponents=1", "--set", "batches=2"},
      {"converge", "--set", "model=linear", "--set", "Ns=10,20,40", "--set", "nev=1", "--set", "solver=dense"},
      {"bench", "--set", "model=linear", "--set", "Ns=10,20", "--set", "nev=1", "--set", "solvers=dense"},
      {"chart", "--set", "model=mathieu", "--set", "N=10", "--set", "chart_x_points=2", "--set", "chart_y_points=2",
       "--set", "solver=dense"}};
  for (auto args : commands) {
    const std::string command = args.front();
    args.insert(args.end(), {"--out", out + "/" + command, "--quiet"});
    CliResult r = run(args);
    ASSERT_EQ(r.status, 0) << command << ": " << r.err;
  }
  CliResult basin = run({"basin", "--set", "N=20", "--set", "basin_x_points=2", "--set", "basin_y_points=2", "--set",
                         "basin_transient=2", "--set", "basin_max_period=2", "--out", out + "/basin", "--quiet"});
  ASSERT_EQ(basin.status, 0) << basin.err;
  int csv_files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.path().extension() != ".csv") continue;
    ++csv_files;
    const std::string text = read_text(entry.path());
    EXPECT_EQ(text.rfind("# delayspec ", 0), 0u) << entry.path();
    EXPECT_TRUE(contains(text, "\n# source_revision: ")) << entry.path();
    EXPECT_TRUE(contains(text, "\n# command: ")) << entry.path();
    EXPECT_TRUE(contains(text, "\n# default: ")) << entry.path();
  }
  // trajectory, poincare, impacts, exponents, section, converge, converge_richardson, bench, chart, basin
  EXPECT_EQ(csv_files, 10);
}

TEST(Scenes, EveryShippedSceneIsAcceptedByRun) {
  // `delayspec run SCENE` validates the whole scene before computing (plan_run): every key must
  // be read by one of its analyses; a scene without `analyses` runs the command reading all keys.
  // The analyses each scene lists (comma-joined):
  const std::map<std::string, std::string> expected = {{"convergence", "converge"},
                                                       {"default", "floquet"},
                                                       {"fig6_1", "basin"},
                                                       {"fig6_2", "sweep"},
                                                       {"fig6_2_zoom", "sweep"},
                                                       {"fig6_3", "simulate"},
                                                       {"fig6_4", "sweep"},
                                                       {"mathieu_chart", "chart"},
                                                       {"paper-period1", "floquet"},
                                                       {"pwsdde-period2", "floquet"},
                                                       {"continue_grazing_e", "continue"},
                                                       {"continue_tau_half_k", "continue"},
                                                       {"continue_mathieu_delta2", "continue"},
                                                       {"continue_mathieu_delta3", "continue"},
                                                       {"continue_pwsdde_k", "continue"},
                                                       {"milling_lobes", "chart"},
                                                       {"milling_lobes_full", "chart"},
                                                       {"milling_variable_pitch", "chart"},
                                                       {"milling_lobes_curves", "boundary"},
                                                       {"milling_point", "converge"},
                                                       {"equations_impact", "floquet"},
                                                       {"equations_two_oscillators", "floquet"},
                                                       {"equations_two_delays", "floquet"},
                                                       {"equilibrium_neuron_ring", "equilibrium"},
                                                       {"mackey_glass_hopf", "equilibrium,continue"},
                                                       {"mackey_glass_orbit", "floquet"},
                                                       {"pyragas_oscillator", "floquet"},
                                                       {"wright_generalised_hopf", "boundary"}};
  const fs::path cache = DELAYSPEC_TEST_MODEL_CACHE;  // equation models compile here
  int scenes = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(DELAYSPEC_SOURCE_DIR) / "data/scenes")) {
    if (entry.path().extension() != ".toml") continue;
    ++scenes;
    const std::string name = entry.path().stem().string();
    delayspec::cli::Config config = delayspec::cli::Config::from_scene_file(entry.path().string());
    if (config.has("equations")) config.set("model_cache", cache.string(), "test");
    delayspec::cli::RunPlan plan;
    ASSERT_NO_THROW(plan = delayspec::cli::plan_run(config)) << name;
    ASSERT_TRUE(expected.count(name)) << "new scene " << name << ": add its analysis here";
    std::string analyses;  // in the scene's order, comma-joined
    for (const std::string& a : plan.analyses) analyses += (analyses.empty() ? "" : ",") + a;
    EXPECT_EQ(analyses, expected.at(name)) << name;
  }
  EXPECT_EQ(scenes, static_cast<int>(expected.size()));
}

TEST(Scenes, Fig63RunsWithRunAtReducedSize) {
  // The reproducer: exit 2 (`control_on_at` unknown to floquet) before the fix.
  const fs::path dir = fresh_dir("keys_fig6_3");
  CliResult r = run({"run", DELAYSPEC_SOURCE_DIR "/data/scenes/fig6_3.toml", "--out", dir.string(), "--set", "N=20",
                     "--set", "control_on_at=20", "--set", "t_start=20", "--set", "t_end=40", "--quiet"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "simulate.json"));
  EXPECT_TRUE(fs::exists(dir / "impacts.csv"));
  EXPECT_TRUE(fs::exists(dir / "run.json"));
}

// Issue 61 item 9: a scene's unknown top-level key with control characters (an escape sequence
// that would recolour or rewrite the terminal) is named with \xNN escapes, as inside [equations],
// by `floquet` and by `run` (its own key check), never raw.
TEST(Keys, AnUnknownKeyWithControlCharactersIsEscapedInTheMessage) {
  const fs::path dir = fresh_dir("keys_control_characters");
  fs::create_directories(dir);
  const fs::path scene = dir / "scene.toml";
  std::ofstream(scene) << "\"nev\\u001b[2J\" = 2\n";
  for (const char* command : {"floquet", "run"}) {
    const CliResult r = run({command, scene.string()});
    EXPECT_EQ(r.status, 2) << command << ": " << r.err;
    EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << command << ": " << r.err;
    EXPECT_TRUE(contains(r.err, "nev\\x1B[2J")) << command << ": " << r.err;
  }
  fs::remove_all(dir);
}
