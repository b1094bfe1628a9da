// `--out DIR` and `--resume` (output_directory.hpp, run_cli.cpp, command_sweep.cpp):
// one run per directory (a held lock is exit 2), DIR/complete.json only for a finished run,
// run.json absent while a run is in progress and after it failed or was killed, --resume
// refusing a point file of other settings and accepting a key stated at its default, a killed
// sweep resumed to the same tables, bad --out / --resume flags, and chart/basin exit 3 with
// their failed points recorded.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "scene/output/atomic_file.hpp"
#include "cli_test_support.hpp"
#include "point_logs.hpp"
#include "scene/keys/config.hpp"
#include "delayspec/errors.hpp"
#include "delayspec_test_paths.hpp"
#include "scene/output/output_directory.hpp"

namespace fs = std::filesystem;

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::contains;
using delayspec::testing::fresh_dir;
using delayspec::testing::read_text;
using delayspec::testing::run;
using delayspec::testing::without_metadata;
using delayspec::testing::forget_points;
using delayspec::testing::logged_line;
using delayspec::testing::logged_points;
using delayspec::testing::logged_records;
using delayspec::testing::point_logs;

std::vector<std::string> with(std::vector<std::string> head, const std::vector<std::string>& tail) {
  head.insert(head.end(), tail.begin(), tail.end());
  return head;
}

// The lock of DIR taken as another delayspec process would (flock on its own open file).
class HeldLock {
 public:
  explicit HeldLock(const fs::path& dir) {
    fs::create_directories(dir);
    fd_ = ::open((dir / delayspec::cli::OutputDirectory::lock_name).c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    held_ = fd_ >= 0 && ::flock(fd_, LOCK_EX | LOCK_NB) == 0;
  }
  ~HeldLock() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool held() const { return held_; }

 private:
  int fd_ = -1;
  bool held_ = false;
};

bool lock_is_free(const fs::path& dir) { return HeldLock(dir).held(); }

// The x-independent columns of a sweep table: the last one (seconds) differs between runs.
std::string without_seconds(const std::string& csv) {
  std::string out, line;
  std::stringstream ss(csv);
  while (std::getline(ss, line))  // the metadata lines (time, scene path) differ between runs
    if (line.rfind('#', 0) != 0) out += line.substr(0, line.rfind(',')) + "\n";
  return out;
}

// The data lines of a CSV (the metadata lines carry times and the scene path).

const std::vector<std::string> kSweep = {"--quiet",         "--set", "model=linear", "--set", "N=10",           "--set",
                                         "periods=20",      "--set", "transient=0",  "--set", "sweep_key=a",    "--set",
                                         "sweep_from=-2",   "--set", "sweep_to=0",   "--set", "sweep_points=5", "--set",
                                         "section_points=4"};

}  // namespace

// A second run into a directory whose lock another run holds stops at once: exit 2 naming DIR,
// nothing written. Once the lock is free, the same command runs.
TEST(OutputDirectory, SecondRunWhileTheLockIsHeldExitsTwo) {
  const fs::path dir = fresh_dir("outdir_held");
  const std::vector<std::vector<std::string>> commands = {
      with({"sweep", "--out", dir.string()}, kSweep),
      {"chart", "--quiet", "--out", dir.string(), "--set", "model=mathieu", "--set", "N=8", "--set", "chart_x_points=2",
       "--set", "chart_y_points=2"},
      {"basin", "--quiet", "--out", dir.string(), "--set", "N=8", "--set", "basin_x_points=2", "--set",
       "basin_y_points=2", "--set", "basin_transient=1"},
      {"simulate", "--out", dir.string(), "--set", "N=8"},
      {"converge", "--out", dir.string(), "--set", "model=linear", "--set", "Ns=8,16,32"},
      {"run", DELAYSPEC_SOURCE_DIR "/data/scenes/default.toml", "--out", dir.string(), "--set", "N=8"},
  };
  {
    HeldLock other(dir);
    ASSERT_TRUE(other.held());
    for (const auto& args : commands) {
      CliResult r = run(args);
      EXPECT_EQ(r.status, 2) << args[0] << ": " << r.err;
      EXPECT_TRUE(contains(r.err, "`--out " + dir.string() + "`: another delayspec run holds this directory")) << r.err;
    }
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1) << "only the lock file";
  }
  CliResult r = run(commands[0]);
  EXPECT_EQ(r.status, 0) << r.err;
  fs::remove_all(dir);
}

// The lock is never opened through a symbolic link (issue 61 item 5): a link planted as
// `DIR/.delayspec-lock` (another user, in a shared directory) pointing elsewhere used to make the
// run create and lock the target. Now: exit 2 naming the link, and no target created.
TEST(OutputDirectory, ALockThatIsASymbolicLinkIsRefusedAndNotFollowed) {
  const fs::path dir = fresh_dir("outdir_lock_link");
  fs::create_directories(dir);
  const fs::path target = dir.parent_path() / "outdir_lock_link_target";
  fs::remove(target);
  fs::create_symlink(target, dir / ".delayspec-lock");
  const CliResult r = run({"simulate", "--out", dir.string(), "--set", "N=8"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err, ".delayspec-lock` is a symbolic link")) << r.err;
  EXPECT_FALSE(fs::exists(target)) << "the link was followed";
  fs::remove_all(dir);
}

// A directory that does not exist yet is created, and locked, by the run's first write, so a run
// stopped by bad input creates nothing. If another run created it meanwhile (holding its lock,
// or already finished), this run writes nothing there.
TEST(OutputDirectory, DirectoryCreatedLaterBelongsToTheRunThatCreatedIt) {
  const fs::path dir = fresh_dir("outdir_later");
  // A write through the run's directory (as a command's, through inv.output).
  auto write_fails = [&](delayspec::cli::OutputDirectory& run, const fs::path& target) {
    try {
      run.write(target, "x\n");
    } catch (const delayspec::BadInput& e) {
      return contains(e.what(), "`--out " + dir.string() + "`: another delayspec run");
    }
    return false;
  };
  {
    delayspec::cli::OutputDirectory mine(dir);
    EXPECT_FALSE(fs::exists(dir));
    HeldLock other(dir);  // another run got there first and is running
    ASSERT_TRUE(other.held());
    EXPECT_TRUE(write_fails(mine, dir / "a.csv"));
    EXPECT_FALSE(fs::exists(dir / "a.csv"));
  }
  fs::remove_all(dir);
  {
    delayspec::cli::OutputDirectory mine(dir);
    fs::create_directories(dir);  // another run came and went
    EXPECT_TRUE(write_fails(mine, dir / "a.csv"));
    EXPECT_FALSE(fs::exists(dir / "a.csv"));
  }
  fs::remove_all(dir);
  {
    delayspec::cli::OutputDirectory mine(dir / "sub");
    mine.write(dir / "sub" / "a.csv", "x\n");  // nobody else: created and locked
    EXPECT_TRUE(fs::exists(dir / "sub" / "a.csv"));
    EXPECT_FALSE(lock_is_free(dir / "sub"));
  }
  EXPECT_TRUE(lock_is_free(dir / "sub"));
  fs::remove_all(dir);
}

// complete.json appears last, for a finished run, and lists its files; a run interrupted
// between two files of its set leaves no complete.json (the earlier run's is gone too).
TEST(OutputDirectory, InterruptedMultiFileOutputHasNoCompleteMarker) {
  const fs::path dir = fresh_dir("outdir_simulate");
  const std::vector<std::string> args = {"simulate", "--out", dir.string(), "--set", "N=8", "--set", "t_end=2"};
  CliResult r = run(args);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto marker = nlohmann::json::parse(read_text(dir / "complete.json"));
  EXPECT_EQ(marker["command"], "simulate");
  EXPECT_EQ(marker["exit_status"], 0);
  EXPECT_EQ(marker["files"], nlohmann::json({"impacts.csv", "poincare.csv", "trajectory.csv"}));
  EXPECT_TRUE(lock_is_free(dir));
  // The second file of the set cannot be written (a non-empty directory stands in its place):
  // the run stops after trajectory.csv, as a killed run would.
  fs::remove(dir / "poincare.csv");
  fs::create_directories(dir / "poincare.csv" / "blocker");
  r = run(args);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(fs::exists(dir / "trajectory.csv"));
  EXPECT_FALSE(fs::exists(dir / "complete.json")) << "an interrupted set must not look complete";
  fs::remove_all(dir);
}

// `run` removes run.json before its first analysis: after a failure the directory has neither
// run.json nor complete.json, although the previous run had both.
TEST(OutputDirectory, RunJsonAbsentAfterAFailedRun) {
  const fs::path dir = fresh_dir("outdir_runjson");
  const std::string scene = DELAYSPEC_SOURCE_DIR "/data/scenes/default.toml";
  CliResult r = run({"run", scene, "--out", dir.string(), "--set", "N=40", "--quiet"});
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_TRUE(fs::exists(dir / "run.json"));
  ASSERT_TRUE(fs::exists(dir / "complete.json"));
  fs::remove(dir / "floquet.json");
  fs::create_directories(dir / "floquet.json" / "blocker");  // the analysis's file cannot be written
  r = run({"run", scene, "--out", dir.string(), "--set", "N=40", "--quiet"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_FALSE(fs::exists(dir / "run.json"));
  EXPECT_FALSE(fs::exists(dir / "complete.json"));
  fs::remove_all(dir);
}

// The real thing: a `run` (floquet, then a sweep) in its own process, killed with SIGKILL in the
// middle of the sweep. While it runs, and after it died: the lock is held only while it lives,
// and neither run.json (from an earlier finished run) nor complete.json is there. `run --resume`
// then completes the sweep with tables identical to an uninterrupted sweep (bit for bit, all
// columns but the wall-clock seconds).
TEST(OutputDirectory, KilledRunIsIncompleteAndResumesToTheSameTables) {
  const fs::path dir = fresh_dir("outdir_killed");
  const fs::path reference = fresh_dir("outdir_killed_reference");
  const fs::path scene = fresh_dir("outdir_killed.toml");
  // ~200 points of several milliseconds each: the sweep runs long enough to be caught mid-way.
  std::ofstream(scene) << "analyses = [\"floquet\", \"sweep\"]\nmodel = \"linear\"\nb = -0.5\nN = 10\nsolver = "
                          "\"dense\"\nnev = 2\nperiods = 4000\ntransient = 0\nsweep_key = \"a\"\nsweep_from = -2\n"
                          "sweep_to = -1\nsweep_points = 200\nsection_points = 4\nthreads = 1\n";
  CliResult first = run({"run", "--out", dir.string(), "--quiet", "--set", "analyses=floquet", "--set", "model=linear",
                         "--set", "N=10", "--set", "solver=dense", "--set", "nev=2"});
  ASSERT_EQ(first.status, 0) << first.err;
  ASSERT_TRUE(fs::exists(dir / "run.json"));

  std::vector<std::string> args = {DELAYSPEC_CLI_PATH, "run", scene.string(), "--out", dir.string(), "--quiet"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t child = 0;
  ASSERT_EQ(posix_spawn(&child, DELAYSPEC_CLI_PATH, &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  // (a line being written does not parse yet, so it is not counted)
  auto points_done = [&] { return logged_records(dir / "points"); };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (points_done() < 3 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  const long seen = points_done();
  // In progress: the lock is held, and nothing claims the set is complete.
  const bool held_while_running = !lock_is_free(dir);
  const bool run_json_while_running = fs::exists(dir / "run.json");
  const bool marker_while_running = fs::exists(dir / "complete.json");
  ::kill(child, SIGKILL);
  int wstatus = 0;
  ::waitpid(child, &wstatus, 0);
  ASSERT_GE(seen, 3) << "the sweep did not start in time";
  ASSERT_TRUE(WIFSIGNALED(wstatus)) << "the run finished before it could be killed: make the sweep longer";
  EXPECT_TRUE(held_while_running);
  EXPECT_FALSE(run_json_while_running);
  EXPECT_FALSE(marker_while_running);
  // Killed: the kernel released the lock; the directory still says incomplete.
  EXPECT_TRUE(lock_is_free(dir));
  EXPECT_FALSE(fs::exists(dir / "run.json"));
  EXPECT_FALSE(fs::exists(dir / "complete.json"));
  EXPECT_FALSE(fs::exists(dir / "exponents.csv"));

  CliResult resumed = run({"run", scene.string(), "--out", dir.string(), "--quiet", "--resume"});
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_TRUE(fs::exists(dir / "run.json"));
  const auto marker = nlohmann::json::parse(read_text(dir / "complete.json"));
  EXPECT_EQ(marker["command"], "run");
  EXPECT_TRUE(contains(marker["files"].dump(), "\"run.json\"")) << marker.dump();
  // the settings the resumed points were checked against belong to the finished set too (issue
  // 61 item 9: the resumed run's complete.json left them out)
  EXPECT_TRUE(contains(marker["files"].dump(), "\"sweep_settings.json\"")) << marker.dump();
  EXPECT_LE(nlohmann::json::parse(read_text(dir / "sweep.json"))["points_computed_now"].get<long>(), 200 - seen);

  CliResult alone = run({"run", scene.string(), "--out", reference.string(), "--quiet"});  // uninterrupted
  ASSERT_EQ(alone.status, 0) << alone.err;
  EXPECT_EQ(without_seconds(read_text(dir / "exponents.csv")), without_seconds(read_text(reference / "exponents.csv")));
  EXPECT_EQ(without_metadata(read_text(dir / "section.csv")), without_metadata(read_text(reference / "section.csv")));
  fs::remove_all(dir);
  fs::remove_all(reference);
  fs::remove(scene);
}

// A point of another sweep (other settings) in the directory's log: --resume refuses it, naming
// the log and the line, instead of merging it into the tables.
TEST(OutputDirectory, ResumeRefusesAPointOfOtherSettings) {
  const fs::path dir = fresh_dir("outdir_foreign");
  const fs::path other = fresh_dir("outdir_foreign_other");
  ASSERT_EQ(run(with({"sweep", "--out", dir.string()}, kSweep)).status, 0);
  ASSERT_EQ(run(with({"sweep", "--out", other.string(), "--set", "seed=9"}, kSweep)).status, 0);
  for (const char* f : {"exponents.csv", "section.csv", "sweep.json", "complete.json"}) fs::remove(dir / f);
  forget_points(dir / "points", {1, 2});
  const std::string foreign = logged_line(other / "points", 2);
  ASSERT_FALSE(foreign.empty());
  const std::vector<fs::path> logs = point_logs(dir / "points");
  ASSERT_EQ(logs.size(), 1u);
  long lines = 0;
  {
    std::ifstream in(logs[0]);
    for (std::string line; std::getline(in, line);) ++lines;
  }
  std::ofstream(logs[0], std::ios::app) << foreign << "\n";
  CliResult r = run(with({"sweep", "--out", dir.string(), "--resume"}, kSweep));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err, logs[0].string() + "` line " + std::to_string(lines + 1) +
                                  " belongs to a sweep with other settings"))
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "exponents.csv"));
  fs::remove_all(dir);
  fs::remove_all(other);
}

// chart and basin keep their points as sweep does (point_files.hpp): with some points gone from
// the log and the table gone, --resume computes only the missing points, and the table is the
// one of the uninterrupted run. A second run without --resume is refused instead of mixing two
// runs.
TEST(OutputDirectory, ChartAndBasinResumeToTheSameTable) {
  const std::vector<std::pair<std::string, std::vector<std::string>>> grids = {
      {"chart",
       {"chart", "--quiet", "--set", "model=mathieu", "--set", "N=10", "--set", "solver=dense", "--set",
        "chart_x_points=3", "--set", "chart_y_points=2"}},
      {"basin",
       {"basin", "--quiet", "--set", "N=10", "--set", "basin_x_points=3", "--set", "basin_y_points=2", "--set",
        "basin_transient=5", "--set", "basin_max_period=2"}}};
  for (const auto& [name, args] : grids) {
    const fs::path dir = fresh_dir("outdir_resume_" + name);
    ASSERT_EQ(run(with(args, {"--out", dir.string()})).status, 0) << name;
    const std::string complete = without_metadata(read_text(dir / (name + ".csv")));
    EXPECT_TRUE(fs::exists(dir / (name + "_settings.json"))) << name;
    EXPECT_EQ(logged_points(dir / (name + "_points")), (std::set<long>{0, 1, 2, 3, 4, 5})) << name;
    CliResult again = run(with(args, {"--out", dir.string()}));
    EXPECT_EQ(again.status, 2) << name;
    // finished: nothing to resume, so no --resume advice (a new run with other keys would fail it)
    EXPECT_TRUE(contains(again.err, "already holds a finished " + name + " (complete.json)")) << again.err;
    EXPECT_FALSE(contains(again.err, "--resume")) << again.err;
    fs::remove(dir / "complete.json");  // as an interrupted run leaves it
    again = run(with(args, {"--out", dir.string()}));
    EXPECT_EQ(again.status, 2) << name;
    EXPECT_TRUE(contains(again.err, "already holds a " + name + ": add --resume")) << again.err;

    fs::remove(dir / (name + ".csv"));
    forget_points(dir / (name + "_points"), {1, 4});
    CliResult resumed = run(with(args, {"--out", dir.string(), "--resume", "--json"}));
    ASSERT_EQ(resumed.status, 0) << resumed.err;
    EXPECT_EQ(logged_records(dir / (name + "_points")), 6) << name;  // the 4 kept and the 2 computed again
    EXPECT_EQ(without_metadata(read_text(dir / (name + ".csv"))), complete) << name;
    EXPECT_EQ(logged_points(dir / (name + "_points")), (std::set<long>{0, 1, 2, 3, 4, 5})) << name;
    fs::remove_all(dir);
  }
}

// A run killed while it wrote a point's line leaves that line cut short: --resume skips it
// (computing the point again) and starts its own records on a new line, so the cut line takes
// no finished point with it.
TEST(OutputDirectory, ResumeSkipsALineCutShortByAKill) {
  const std::vector<std::string> args = {"chart", "--quiet", "--set", "model=mathieu", "--set", "N=10", "--set",
                                         "solver=dense", "--set", "chart_x_points=3", "--set", "chart_y_points=2"};
  const fs::path dir = fresh_dir("outdir_cut_line");
  ASSERT_EQ(run(with(args, {"--out", dir.string()})).status, 0);
  const std::string complete = without_metadata(read_text(dir / "chart.csv"));
  const fs::path points = dir / "chart_points";
  const std::string line3 = logged_line(points, 3);
  ASSERT_GT(line3.size(), 20u);
  fs::remove(dir / "complete.json");
  fs::remove(dir / "chart.csv");
  forget_points(points, {3, 5});
  const std::vector<fs::path> logs = point_logs(points);
  ASSERT_EQ(logs.size(), 1u);
  std::ofstream(logs[0], std::ios::app) << line3.substr(0, 20);  // no newline: the write was cut
  CliResult resumed = run(with(args, {"--out", dir.string(), "--resume"}));
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_EQ(without_metadata(read_text(dir / "chart.csv")), complete);
  EXPECT_EQ(logged_points(points), (std::set<long>{0, 1, 2, 3, 4, 5}));
  // The 4 kept, the cut line on its own, then the 2 computed again.
  std::ifstream in(logs[0]);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 7u);
  EXPECT_EQ(lines[4], line3.substr(0, 20));
  EXPECT_EQ(logged_records(points), 6);
  fs::remove_all(dir);
}

// A chart point's record is untrusted input like any results file: a verdict word that is no
// verdict (edited by hand, or written by another program) is not taken into the table; the point
// is computed again and the table is the uninterrupted run's.
TEST(OutputDirectory, ResumeComputesAgainAChartPointWhoseVerdictIsNoVerdict) {
  const std::vector<std::string> args = {"chart", "--quiet", "--set", "model=mathieu", "--set", "N=10", "--set",
                                         "solver=dense", "--set", "chart_x_points=3", "--set", "chart_y_points=2"};
  const fs::path dir = fresh_dir("outdir_bad_verdict");
  ASSERT_EQ(run(with(args, {"--out", dir.string()})).status, 0);
  const std::string complete = without_metadata(read_text(dir / "chart.csv"));
  fs::remove(dir / "complete.json");
  fs::remove(dir / "chart.csv");
  const std::vector<fs::path> logs = point_logs(dir / "chart_points");
  ASSERT_EQ(logs.size(), 1u);
  std::string log = read_text(logs[0]);
  const std::string word = "\"verdict\":\"undecided\"";
  const size_t at = log.find(word);
  ASSERT_NE(at, std::string::npos) << log;
  log.replace(at, word.size(), "\"verdict\":\"bogus\"");
  std::ofstream(logs[0], std::ios::trunc) << log;
  const CliResult resumed = run(with(args, {"--out", dir.string(), "--resume", "--json"}));
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_FALSE(contains(resumed.out, "bogus")) << resumed.out;
  EXPECT_EQ(without_metadata(read_text(dir / "chart.csv")), complete);
  fs::remove_all(dir);
}

// The settings --resume compares are the effective ones: a scene or --set stating keys at their
// default values (in any spelling of the number) resumes a sweep made without them.
TEST(OutputDirectory, ResumeAcceptsExplicitDefaults) {
  const fs::path dir = fresh_dir("outdir_defaults");
  CliResult full = run(with({"sweep", "--out", dir.string()}, kSweep));
  ASSERT_EQ(full.status, 0) << full.err;
  const std::string complete_csv = read_text(dir / "exponents.csv");
  for (const char* f : {"exponents.csv", "section.csv", "sweep.json"}) fs::remove(dir / f);
  forget_points(dir / "points", {1});
  const fs::path scene = dir.string() + ".toml";
  std::ofstream(scene) << "seed = 1\nevents = \"on\"\nqr_every = 1\n";  // the defaults (lyapunov_settings.cpp)
  CliResult r = run(with(with({"sweep", scene.string(), "--out", dir.string(), "--resume", "--json"}, kSweep),
                         {"--set", "b=0.50", "--set", "sweep_to=0.0", "--set", "tau=1e0"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["points_computed_now"], 1);
  EXPECT_EQ(without_seconds(read_text(dir / "exponents.csv")), without_seconds(complete_csv));
  // A value that differs is still refused, naming the key and both values.
  forget_points(dir / "points", {1});
  r = run(with({"sweep", "--out", dir.string(), "--resume", "--set", "b=0.6"}, kSweep));
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "`b` (now \"0.6\", the sweep's \"0.5\")")) << r.err;
  fs::remove_all(dir);
  fs::remove(scene);
}

TEST(OutputDirectory, EffectiveValuesAreCanonical) {
  delayspec::cli::Config given, left_out;
  given.set("b", "-2.0", "--set");
  given.set("N", "040", "--set");
  EXPECT_EQ(given.get_double("b", 0.5), -2);
  EXPECT_EQ(given.get_int("N", 100), 40);
  EXPECT_EQ(given.effective_values(), (std::map<std::string, std::string>{{"N", "40"}, {"b", "-2"}}));
  left_out.get_double("b", -2);
  left_out.get_int("N", 40);
  EXPECT_EQ(left_out.effective_values(), given.effective_values());
}

struct FlagCase {
  const char* name;
  std::vector<std::string> args;
  const char* expected;  // part of the message
};
void PrintTo(const FlagCase& c, std::ostream* os) { *os << c.name; }
class OutputFlags : public ::testing::TestWithParam<FlagCase> {};

TEST_P(OutputFlags, ExitTwoNamingTheFlagAndTheCommand) {
  CliResult r = run(GetParam().args);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err, GetParam().expected)) << r.err;
}

// clang-format off
INSTANTIATE_TEST_SUITE_P(Flags, OutputFlags, ::testing::Values(
    FlagCase{"empty_out", {"sweep", "--out", "", "--set", "sweep_key=a"}, "`--out ''`: the directory name is empty"},
    FlagCase{"out_without_value", {"chart", "--out="}, "--out"},  // CLI11's own parse error
    FlagCase{"floquet_out", {"floquet", "--out", "somewhere"}, "`--out somewhere`: `floquet` writes no files"},
    FlagCase{"lyapunov_out", {"lyapunov", "--out", "somewhere"}, "`--out somewhere`: `lyapunov` writes no files"},
    FlagCase{"chart_resume_nothing_there", {"chart", "--out", "somewhere", "--resume", "--set", "model=mathieu"},
             "`--resume`: `somewhere/chart_settings.json` not found (no chart to resume there)"},
    FlagCase{"basin_resume_nothing_there", {"basin", "--out", "somewhere", "--resume"},
             "`--resume`: `somewhere/basin_settings.json` not found (no basin to resume there)"},
    FlagCase{"simulate_resume", {"simulate", "--out", "somewhere", "--resume"}, "`--resume`: `simulate` has nothing"},
    FlagCase{"converge_resume", {"converge", "--out", "somewhere", "--resume"}, "`--resume`: `converge` has nothing"},
    FlagCase{"floquet_resume", {"floquet", "--resume"}, "`--resume`: `floquet` has nothing to resume"},
    FlagCase{"resume_without_out", {"sweep", "--resume"}, "`--resume` needs `--out DIR`"},
    FlagCase{"run_resume_no_sweep", {"run", DELAYSPEC_SOURCE_DIR "/data/scenes/default.toml", "--out", "somewhere", "--resume"},
             "`--resume`: no analysis of this scene has anything to resume"}));
// clang-format on

// chart and basin: a failing point is recorded in the output (null / nan, its reason), the other
// points still run, and the command exits 3 after writing everything, as sweep does.
TEST(OutputDirectory, ChartAndBasinExitThreeWithFailedPointsRecorded) {
  const fs::path dir = fresh_dir("outdir_failing");
  // impact model, an orbit by simulation allowed 2 periods: it cannot settle at any point
  CliResult chart = run({"chart",
                         "--json",
                         "--quiet",
                         "--out",
                         dir.string(),
                         "--set",
                         "model=impact",
                         "--set",
                         "N=8",
                         "--set",
                         "chart_x=k",
                         "--set",
                         "chart_y=zeta",
                         "--set",
                         "chart_x_range=0,0.2",
                         "--set",
                         "chart_y_range=0,0.1",
                         "--set",
                         "chart_x_points=2",
                         "--set",
                         "chart_y_points=2",
                         "--set",
                         "orbit=simulate",
                         "--set",
                         "orbit_max_periods=2"});
  EXPECT_EQ(chart.status, 3) << chart.err;
  EXPECT_TRUE(contains(chart.err, "numerical failure at 4 of 4 point(s)")) << chart.err;
  auto j = nlohmann::json::parse(chart.out);
  EXPECT_EQ(j["failed_points"], 4);
  EXPECT_TRUE(j["rows"][0]["spectral_radius"].is_null());
  EXPECT_TRUE(contains(j["rows"][0]["failure"].get<std::string>(), "not settled"));
  EXPECT_TRUE(contains(read_text(dir / "chart.csv"), ",nan\n"));
  EXPECT_EQ(nlohmann::json::parse(read_text(dir / "complete.json"))["exit_status"], 3);
  // linear x' = a x + b x(t - 1): a = 10 overflows within the 400-period transient, a = -1 decays
  CliResult basin = run({"basin",
                         "--json",
                         "--quiet",
                         "--out",
                         dir.string(),
                         "--set",
                         "model=linear",
                         "--set",
                         "N=8",
                         "--set",
                         "basin_x=a",
                         "--set",
                         "basin_y=b",
                         "--set",
                         "basin_x_range=-1,10",
                         "--set",
                         "basin_y_range=0,1",
                         "--set",
                         "basin_x_points=2",
                         "--set",
                         "basin_y_points=2"});
  EXPECT_EQ(basin.status, 3) << basin.err;
  EXPECT_TRUE(contains(basin.err, "numerical failure at 2 of 4 point(s), first: (10, 0)")) << basin.err;
  j = nlohmann::json::parse(basin.out);
  EXPECT_EQ(j["failed_points"], 2);
  EXPECT_EQ(j["rows"][0]["period"], 1);
  EXPECT_TRUE(j["rows"][1]["period"].is_null());
  EXPECT_TRUE(contains(read_text(dir / "basin.csv"), "10,0,nan,nan\n"));
  fs::remove_all(dir);
}

// `run`: an analysis exiting 3 keeps its file, the next analysis still runs, and run exits 3
// with a manifest naming each analysis's exit status.
TEST(OutputDirectory, RunKeepsGoingAfterAnAnalysisExitsThree) {
  const fs::path dir = fresh_dir("outdir_run3");
  CliResult r = run({"run",        "--out",
                     dir.string(), "--quiet",
                     "--set",      "analyses=basin,floquet",
                     "--set",      "model=linear",
                     "--set",      "N=8",
                     "--set",      "basin_x=a",
                     "--set",      "basin_y=b",
                     "--set",      "basin_x_range=-1,10",
                     "--set",      "basin_y_range=0,1",
                     "--set",      "basin_x_points=2",
                     "--set",      "basin_y_points=2",
                     "--set",      "solver=dense",
                     "--set",      "nev=2"});
  EXPECT_EQ(r.status, 3) << r.err;
  const auto manifest = nlohmann::json::parse(read_text(dir / "run.json"));
  EXPECT_EQ(manifest["analyses"][0]["exit_status"], 3);
  EXPECT_EQ(manifest["analyses"][1]["exit_status"], 0);
  EXPECT_TRUE(fs::exists(dir / "basin.json"));
  EXPECT_TRUE(fs::exists(dir / "floquet.json"));
  fs::remove_all(dir);
}

// Issue 31: a chart whose bad input shows only when a point runs (tau = 1.5 with period = 1 needs
// N divisible by 3; N = 10) stopped after chart_settings.json and the first point were written,
// and the same command then demanded --resume. A run stopped by bad input leaves nothing behind:
// the directory it created is gone; in a directory that existed, the files it created are.
TEST(OutputDirectory, BadInputFoundWhenAPointRunsLeavesNothingBehind) {
  const fs::path dir = fresh_dir("outdir_bad_point");
  const std::vector<std::string> args = {
      "chart",          "--quiet",         "--out", dir.string(),      "--set", "model=linear",
      "--set",          "period=1",        "--set", "N=10",            "--set", "solver=dense",
      "--set",          "nev=1",           "--set", "threads=1",       "--set", "chart_x=tau",
      "--set",          "chart_x_range=1,2", "--set", "chart_x_points=3", "--set", "chart_y=a",
      "--set",          "chart_y_range=-1,0", "--set", "chart_y_points=2"};
  for (int attempt = 0; attempt < 2; ++attempt) {  // the same command twice: the same answer
    const CliResult r = run(args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_TRUE(contains(r.err, "N divisible by 3")) << r.err;
    EXPECT_FALSE(contains(r.err, "--resume")) << "attempt " << attempt << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir)) << "attempt " << attempt << ": the run created " << dir;
  }
  // A directory that existed (with a file of the user's): it stays, with only that file in it
  // (and the lock file, which always stays).
  fs::create_directories(dir);
  std::ofstream(dir / "notes.txt") << "mine\n";
  const CliResult r = run(args);
  EXPECT_EQ(r.status, 2) << r.err;
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.insert(entry.path().filename().string());
  EXPECT_EQ(names, (std::set<std::string>{".delayspec-lock", "notes.txt"}));
  EXPECT_FALSE(contains(run(args).err, "--resume"));
  fs::remove_all(dir);
}

// Issue 31: a write past the file-size limit (`ulimit -f`) raised SIGXFSZ, whose default action
// killed the program in the middle of the write. The program ignores it: the write fails with
// EFBIG, the run stops with exit 2 naming the file, and nothing of it is left (the directory it
// created is removed), so no half-written result can look complete.
TEST(OutputDirectory, FileSizeLimitIsBadInputNamingTheFile) {
  const fs::path dir = fresh_dir("outdir_fsize");
  // 1 block (512 bytes in dash, 1024 in bash) against a trajectory of some 20 KB (N = 8, t_end = 40).
  const std::string command = "ulimit -f 1; exec '" + std::string(DELAYSPEC_CLI_PATH) + "' simulate --quiet --out '" +
                              dir.string() + "' --set N=8 --set t_end=40 2>&1 >/dev/null";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string err;
  char buffer[4096];
  for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) err.append(buffer, n);
  const int status = ::pclose(pipe);
  // Before: killed by SIGXFSZ (the shell exec'd the program, so the signal is the status).
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0) << ": " << err;
  EXPECT_EQ(WEXITSTATUS(status), 2) << err;
  EXPECT_TRUE(contains(err, "cannot write `" + dir.string() + "/")) << err;
  EXPECT_TRUE(contains(err, "File too large")) << err;
  EXPECT_FALSE(fs::exists(dir)) << "a stopped run left " << dir;
}
