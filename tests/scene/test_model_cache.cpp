// The compiled-model cache against untrusted scenes and other users (issue 31): a scene never
// chooses where code is loaded from; an object in the cache is opened only when it is the one this
// program compiled (its recorded checksum), never through a link, and only from a directory that
// is the user's alone; the per-user fallback; the headers' contents in the cache key; the
// compiler runs as a child that dies with delayspec, within a time limit, and whose output is
// checked before it is cached. The attacks are the reproducers of the issue: each planted object's
// constructor writes a marker file, which must never appear.
//
// Fake compilers (shell scripts named by DELAYSPEC_CXX) stand in for g++ where the test is about
// the process or the output rather than the model: nothing here waits for a real compile.
#include <gtest/gtest.h>
#include <signal.h>
#include <linux/fs.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"
#include "delayspec_test_paths.hpp"
#include "scene/equations/equation_plugin.hpp"
#include "scene/equations/model_cache.hpp"
#include "equation_toolchain.hpp"
#include "delayspec/errors.hpp"

namespace {

namespace fs = std::filesystem;
using delayspec::testing::CliResult;
using delayspec::testing::contains;
using delayspec::testing::fresh_dir;
using delayspec::testing::read_text;
using delayspec::testing::run;

const char* kEquations = R"([equations]
state = ["x"]
parameters = { a = -1, b = 0.5 }
period = "1"
delay = "1"
rhs = ["a*x + b*x_tau"]
)";

// Sets an environment variable for the scope (the CLI runs in this process).
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_) ::setenv(name_, old_->c_str(), 1);
    else ::unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

fs::path script(const fs::path& p, const std::string& body) {
  write(p, "#!/bin/sh\n" + body);
  fs::permissions(p, fs::perms::owner_all);
  return p;
}

class ModelCache : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fresh_dir(std::string("model_cache_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    marker_ = dir_ / "MARKER";
    // A compiler that compiles nothing: it leaves the cache entry's source, whose name the
    // planting below needs, and fails.
    failing_compiler_ = script(dir_ / "failing-cc", "echo 'fake compiler: no' >&2\nexit 1\n");
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A shared object whose constructor writes the marker: what an attacker plants.
  fs::path planted_object() {
    const fs::path c = dir_ / "planted.c", so = dir_ / "planted.so";
    write(c, "#include <stdio.h>\n__attribute__((constructor)) static void planted(void) {\n  FILE* f = fopen(\"" +
                 marker_.string() + "\", \"w\");\n  if (f) fclose(f);\n}\n");
    const std::string command =
        std::string(DELAYSPEC_PLUGIN_CXX) + " -x c -shared -fPIC -o " + so.string() + " " + c.string();
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
    return so;
  }

  // The name eq-HASH of the entry the scene's model gets in `cache` with the failing compiler.
  std::string entry_name(const fs::path& scene, const fs::path& cache) {
    const ScopedEnv cxx("DELAYSPEC_CXX", failing_compiler_.string());
    const CliResult r = run({"floquet", scene.string(), "--set", "model_cache=" + cache.string(), "--set", "N=20"});
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_TRUE(contains(r.err, "fake compiler: no")) << r.err;
    for (const auto& e : fs::directory_iterator(cache))
      if (e.path().extension() == ".cpp") return e.path().stem().string();
    ADD_FAILURE() << "no source in " << cache;
    return "";
  }

  fs::path dir_, marker_, failing_compiler_;
};

TEST_F(ModelCache, AScenesModelCacheIsRefusedAndItsPlantedObjectNeverLoaded) {
  // The downloaded folder: scene.toml naming its own cache, which holds eq-HASH.{cpp,so} with
  // the right HASH and source and a planted object.
  const fs::path cache = dir_ / "downloaded" / "cache";
  const fs::path probe = dir_ / "probe.toml";
  write(probe, std::string("model = \"equations\"\n") + kEquations);
  const std::string name = entry_name(probe, cache);
  ASSERT_FALSE(name.empty());
  fs::copy_file(planted_object(), cache / (name + ".so"));
  const fs::path scene = dir_ / "downloaded" / "scene.toml";
  write(scene, "model = \"equations\"\nmodel_cache = \"" + cache.string() + "\"\n" + kEquations);

  const ScopedEnv cxx("DELAYSPEC_CXX", failing_compiler_.string());
  const CliResult r = run({"floquet", scene.string(), "--set", "N=20"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "`model_cache` in the scene")) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_FALSE(fs::exists(marker_)) << "the planted object was loaded";
}

TEST_F(ModelCache, AnObjectThisProgramDidNotCompileIsNeverLoaded) {
  // The cache the user names on the command line, with an object put there by hand (or by an
  // attacker with the user's rights for a moment): no recorded checksum, so it is compiled anew
  // (here by a compiler that fails, so the run ends with exit 2) and never opened.
  const fs::path cache = dir_ / "cache";
  const fs::path scene = dir_ / "scene.toml";
  write(scene, std::string("model = \"equations\"\n") + kEquations);
  const std::string name = entry_name(scene, cache);
  ASSERT_FALSE(name.empty());
  fs::copy_file(planted_object(), cache / (name + ".so"));
  // A checksum file that does not match the object does not help it either.
  write(cache / (name + ".sum"), "fnv1a64 0123456789abcdef 16\n");

  const ScopedEnv cxx("DELAYSPEC_CXX", failing_compiler_.string());
  // Another parameter value (the same table text would be the process's loaded model).
  const CliResult r = run({"floquet", scene.string(), "--set", "model_cache=" + (dir_ / "." / "cache").string(),
                           "--set", "N=20", "--set", "a=-2"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "did not compile")) << r.err;
  EXPECT_FALSE(fs::exists(marker_)) << "the planted object was loaded";
}

TEST_F(ModelCache, EntriesAreNeverOpenedThroughASymbolicLink) {
  const fs::path cache = dir_ / "cache";
  const fs::path scene = dir_ / "scene.toml";
  write(scene, std::string("model = \"equations\"\n") + kEquations);
  const std::string name = entry_name(scene, cache);
  ASSERT_FALSE(name.empty());
  const fs::path planted = planted_object();
  for (const char* entry : {".so", ".lock"}) {
    SCOPED_TRACE(entry);
    fs::remove(cache / (name + ".sum"));
    fs::remove(cache / (name + ".so"));
    fs::remove(cache / (name + ".lock"));
    fs::create_symlink(planted, cache / (name + entry));
    // With a recorded checksum the object is opened (a wrong one: the link must fail first).
    write(cache / (name + ".sum"), "fnv1a64 0123456789abcdef 16\n");
    const ScopedEnv cxx("DELAYSPEC_CXX", failing_compiler_.string());
    const CliResult r = run({"floquet", scene.string(), "--set", "model_cache=" + cache.string() + "/", "--set",
                             "N=20", "--set", std::string("b=") + (entry[1] == 's' ? "0.25" : "0.125")});
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_TRUE(contains(r.err, "symbolic link")) << r.err;
    EXPECT_FALSE(fs::exists(marker_)) << "the planted object was loaded";
    fs::remove(cache / (name + entry));
  }
}

TEST_F(ModelCache, ADirectoryOthersCanWriteOrOwnIsRefused) {
  const fs::path scene = dir_ / "scene.toml";
  write(scene, std::string("model = \"equations\"\n") + kEquations);
  const fs::path open_cache = dir_ / "open";
  fs::create_directories(open_cache);
  fs::permissions(open_cache, fs::perms::all);  // 0777
  const CliResult r = run({"floquet", scene.string(), "--set", "model_cache=" + open_cache.string(), "--set", "N=20"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "`model_cache = " + open_cache.string() + "`")) << r.err;
  EXPECT_TRUE(contains(r.err, "mode 0777")) << r.err;
  if (::geteuid() == 0) {  // root can give a directory away; another user cannot, and needs not to
    const fs::path theirs = dir_ / "theirs";
    fs::create_directories(theirs);
    fs::permissions(theirs, fs::perms::owner_all, fs::perm_options::replace);
    ASSERT_EQ(::chown(theirs.c_str(), 65534, 65534), 0);
    const CliResult other = run({"floquet", scene.string(), "--set", "model_cache=" + theirs.string(), "--set", "N=20"});
    EXPECT_EQ(other.status, 2) << other.err;
    EXPECT_TRUE(contains(other.err, "owner uid 65534")) << other.err;
  }
}

TEST_F(ModelCache, TheFallbackIsPerUserAndPrivate) {
  // HOME and XDG_CACHE_HOME unset: TMPDIR/delayspec-cache-UID, never the shared
  // TMPDIR/delayspec-cache of earlier versions, and refused when someone else made it first.
  const fs::path tmp = dir_ / "tmp";
  const fs::path shared = tmp / "delayspec-cache";
  fs::create_directories(shared);
  fs::permissions(shared, fs::perms::all);
  const fs::path mine = tmp / ("delayspec-cache-" + std::to_string(::geteuid()));
  const fs::path scene = dir_ / "scene.toml";
  write(scene, std::string("model = \"equations\"\n") + kEquations);
  const char* home = std::getenv("HOME");
  const std::string saved_home = home ? home : "";
  ::unsetenv("HOME");
  const ScopedEnv xdg("XDG_CACHE_HOME", "");
  const ScopedEnv tmpdir("TMPDIR", tmp.string());
  const ScopedEnv cxx("DELAYSPEC_CXX", failing_compiler_.string());
  const CliResult first = run({"floquet", scene.string(), "--set", "N=20"});
  EXPECT_EQ(first.status, 2) << first.err;
  EXPECT_TRUE(contains(first.err, "fake compiler: no")) << first.err;
  EXPECT_TRUE(fs::is_empty(shared));
  ASSERT_TRUE(fs::is_directory(mine));
  EXPECT_EQ(fs::status(mine).permissions() & fs::perms::all, fs::perms::owner_all);
  // Someone else's (here: writable by all) folder of that name is refused, naming the key.
  fs::remove_all(mine);
  fs::create_directories(mine);
  fs::permissions(mine, fs::perms::all);
  const CliResult second = run({"floquet", scene.string(), "--set", "N=20", "--set", "a=-3"});
  if (!saved_home.empty()) ::setenv("HOME", saved_home.c_str(), 1);
  EXPECT_EQ(second.status, 2) << second.err;
  EXPECT_TRUE(contains(second.err, "`model_cache = " + mine.string() + "`")) << second.err;
}

TEST_F(ModelCache, ACompilerThatWritesNothingOrGarbageCachesNothing) {
  const fs::path scene = dir_ / "scene.toml";
  write(scene, std::string("model = \"equations\"\n") + kEquations);
  const fs::path cache = dir_ / "cache";
  {
    const ScopedEnv cxx("DELAYSPEC_CXX", script(dir_ / "silent-cc", "exit 0\n").string());
    const CliResult r = run({"floquet", scene.string(), "--set", "model_cache=" + cache.string(), "--set", "N=20"});
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_TRUE(contains(r.err, "wrote no object")) << r.err;
  }
  {
    // Writes text where the object belongs (the argument after -o).
    const ScopedEnv cxx("DELAYSPEC_CXX",
                        script(dir_ / "garbage-cc", "while [ \"$1\" != -o ]; do shift; done\necho garbage > \"$2\"\n")
                            .string());
    const CliResult r = run({"floquet", scene.string(), "--set", "model_cache=" + cache.string(), "--set", "N=20",
                             "--set", "a=-2"});
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_TRUE(contains(r.err, "not a loadable shared object")) << r.err;
  }
  {
    // A shared object, but not a model: it lacks the entry points (and the version).
    const fs::path c = dir_ / "other.c", so = dir_ / "other.so";
    write(c, "int not_a_model(void) { return 1; }\n");
    const std::string build = std::string(DELAYSPEC_PLUGIN_CXX) + " -x c -shared -fPIC -o " + so.string() + " " +
                              c.string();
    ASSERT_EQ(std::system(build.c_str()), 0) << build;
    const ScopedEnv cxx("DELAYSPEC_CXX", script(dir_ / "other-cc", "while [ \"$1\" != -o ]; do shift; done\ncp " +
                                                                       so.string() + " \"$2\"\n")
                                             .string());
    const CliResult r = run({"floquet", scene.string(), "--set", "model_cache=" + cache.string(), "--set", "N=20",
                             "--set", "a=-3"});
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_TRUE(contains(r.err, "lacks `delayspec_equation_version`")) << r.err;
  }
  for (const auto& e : fs::directory_iterator(cache)) {
    const std::string file = e.path().filename().string();
    EXPECT_FALSE(contains(file, ".so")) << "left in the cache: " << file;
  }
}

// The program as a child process, with `env` added to its environment; its pid.
pid_t start_program(const std::vector<std::string>& args, const std::vector<std::string>& env, const fs::path& err) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    for (const auto& e : env) ::putenv(const_cast<char*>(e.c_str()));
    std::freopen(err.c_str(), "w", stderr);
    std::freopen("/dev/null", "w", stdout);
    std::vector<char*> argv = {const_cast<char*>(DELAYSPEC_CLI_PATH)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(DELAYSPEC_CLI_PATH, argv.data());
    ::_exit(127);
  }
  return pid;
}

TEST_F(ModelCache, TheCompilerDiesWithTheProgramAndWithinItsTimeLimit) {
  // A "compiler" whose own child outlives it by seconds (as cc1plus outlives a killed g++) and
  // then writes the marker: it must be killed with the program.
  const fs::path slow = script(dir_ / "slow-cc", "(sleep 3; touch " + marker_.string() + ") &\nwait\n");
  const fs::path scene = dir_ / "scene.toml";
  write(scene, std::string("model = \"equations\"\n") + kEquations);
  const fs::path cache = dir_ / "cache";
  const std::vector<std::string> env = {"DELAYSPEC_CXX=" + slow.string()};
  const std::vector<std::string> args = {"floquet", scene.string(), "--set", "model_cache=" + cache.string(), "--set",
                                         "N=20"};
  {
    const pid_t pid = start_program(args, env, dir_ / "err1");
    std::this_thread::sleep_for(std::chrono::milliseconds(800));  // the compiler has started
    ASSERT_EQ(::kill(pid, SIGTERM), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
  }
  {
    // The time limit: the run ends with exit 2 naming it, the compiler's whole group killed.
    std::vector<std::string> limited = env;
    limited.push_back("DELAYSPEC_COMPILE_TIMEOUT=0.5");
    const pid_t pid = start_program(args, limited, dir_ / "err2");
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << status;
    EXPECT_TRUE(contains(read_text(dir_ / "err2"), "DELAYSPEC_COMPILE_TIMEOUT")) << read_text(dir_ / "err2");
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(3500));
  EXPECT_FALSE(fs::exists(marker_)) << "the compiler's child outlived delayspec";
  // The killed run's temporary object (the slow compiler never wrote one) and no stray files.
  for (const auto& e : fs::directory_iterator(cache))
    EXPECT_FALSE(contains(e.path().filename().string(), ".so")) << e.path();
}

// SIGKILL, which delayspec cannot catch (issue 61 item 4: `kill -9` during a compile left cc1plus
// running to completion): the compiler's whole group still dies with it, the driver's children too.
TEST_F(ModelCache, TheCompilerDiesWithTheProgramKilledBySigkill) {
  const fs::path started = dir_ / "started";
  const fs::path slow =
      script(dir_ / "slow-cc", "touch " + started.string() + "\n(sleep 3; touch " + marker_.string() + ") &\nwait\n");
  const fs::path scene = dir_ / "scene.toml";
  write(scene, std::string("model = \"equations\"\n") + kEquations);
  const std::vector<std::string> args = {"floquet", scene.string(), "--set", "model_cache=" + (dir_ / "cache").string(),
                                         "--set", "N=20"};
  const pid_t pid = start_program(args, {"DELAYSPEC_CXX=" + slow.string()}, dir_ / "err");
  for (int i = 0; i < 600 && !fs::exists(started); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_TRUE(fs::exists(started)) << "the compiler did not start within 30 s: " << read_text(dir_ / "err");
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // its child is running
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << status;
  std::this_thread::sleep_for(std::chrono::milliseconds(3500));
  EXPECT_FALSE(fs::exists(marker_)) << "the compiler's child outlived delayspec killed by SIGKILL";
}

TEST_F(ModelCache, AStaleTemporaryIsRemovedUnderTheLock) {
  const fs::path scene = dir_ / "scene.toml";
  write(scene, std::string("model = \"equations\"\n") + kEquations);
  const fs::path cache = dir_ / "cache";
  const std::string name = entry_name(scene, cache);
  ASSERT_FALSE(name.empty());
  const fs::path stale = cache / (name + ".so.tmp999999.so");
  write(stale, "left by a run killed while it compiled");
  const ScopedEnv cxx("DELAYSPEC_CXX", failing_compiler_.string());
  const CliResult r = run({"floquet", scene.string(), "--set", "model_cache=" + cache.string(), "--set", "N=20",
                           "--set", "a=-2"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_FALSE(fs::exists(stale));
}

// Makes `dir` read-only for this process, root included: the immutable attribute where the file
// system and the rights allow it, else mode 0500 (enough for a user who is not root).
bool make_read_only(const fs::path& dir, bool on) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  int flags = 0;
  bool done = fd >= 0 && ::ioctl(fd, FS_IOC_GETFLAGS, &flags) == 0;
  if (done) {
    flags = on ? (flags | FS_IMMUTABLE_FL) : (flags & ~FS_IMMUTABLE_FL);
    done = ::ioctl(fd, FS_IOC_SETFLAGS, &flags) == 0;
  }
  if (fd >= 0) ::close(fd);
  if (!done) fs::permissions(dir, on ? fs::perms::owner_read | fs::perms::owner_exec : fs::perms::owner_all,
                             fs::perm_options::replace);
  return done || ::geteuid() != 0;
}

TEST_F(ModelCache, AReadOnlyCacheServesWhatItHolds) {
  const fs::path scene = dir_ / "scene.toml";
  write(scene, std::string("model = \"equations\"\n") + kEquations);
  const fs::path cache = dir_ / "cache";
  const std::vector<std::string> args = {"floquet", scene.string(), "--set", "model_cache=" + cache.string(),
                                         "--set", "N=20", "--set", "solver=dense"};
  int status = 0;
  const pid_t compile = start_program(args, {}, dir_ / "err1");  // a real compile
  ASSERT_EQ(::waitpid(compile, &status, 0), compile);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_text(dir_ / "err1");
  for (const auto& e : fs::directory_iterator(cache))
    if (e.path().extension() == ".lock") fs::remove(e.path());  // a read-only cache cannot make one
  ASSERT_TRUE(make_read_only(cache, true)) << "cannot make a directory read-only for root here";
  const pid_t hit = start_program(args, {}, dir_ / "err2");  // no compile: it could write nothing
  ASSERT_EQ(::waitpid(hit, &status, 0), hit);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_text(dir_ / "err2");
  // A model it does not hold: refused, saying why.
  std::vector<std::string> other = args;
  write(dir_ / "other.toml", std::string("model = \"equations\"\n") + kEquations + "history = { x = \"2\" }\n");
  other[1] = (dir_ / "other.toml").string();
  const pid_t miss = start_program(other, {}, dir_ / "err3");
  ASSERT_EQ(::waitpid(miss, &status, 0), miss);
  make_read_only(cache, false);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << read_text(dir_ / "err3");
  EXPECT_TRUE(contains(read_text(dir_ / "err3"), "read-only")) << read_text(dir_ / "err3");
}

TEST_F(ModelCache, HeadersComeOnlyFromTheBuildOrASafelyOwnedInstall) {
  // The build tree: exactly the include paths compiled in, whatever lies beside the library.
  const auto build = delayspec::cli::model_headers(DELAYSPEC_PLUGIN_BUILD_LIBDIR);
  std::vector<std::string> compiled_in;
  std::stringstream list(DELAYSPEC_PLUGIN_BUILD_INCLUDES);
  for (std::string dir; std::getline(list, dir, ';');) compiled_in.push_back(dir);
  EXPECT_EQ(build.include_dirs, compiled_in);
  // A library elsewhere is an installed delayspec: LIBDIR/../include, only when nobody but its
  // owner (root or this user) can write it. A world-writable folder holding a planted
  // delayspec/version.hpp (a build tree in /tmp, say) is refused, not compiled against.
  const fs::path prefix = dir_ / "prefix";
  fs::create_directories(prefix / "lib");
  write(prefix / "include" / "delayspec" / "version.hpp", "#error planted\n");
  fs::permissions(prefix / "include" / "delayspec", fs::perms::all);
  EXPECT_THROW(delayspec::cli::model_headers(prefix / "lib"), delayspec::BadInput);
  fs::permissions(prefix / "include" / "delayspec",
                  fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec | fs::perms::others_read |
                      fs::perms::others_exec,
                  fs::perm_options::replace);
  // PREFIX/include itself, searched before the system's headers: world-writable, a planted
  // `cmath` there would be compiled into the model (issue 61 item 4). Refused likewise.
  const fs::perms include_perms = fs::status(prefix / "include").permissions();
  fs::permissions(prefix / "include", fs::perms::all);
  try {
    delayspec::cli::model_headers(prefix / "lib");
    ADD_FAILURE() << "a world-writable PREFIX/include was accepted";
  } catch (const delayspec::BadInput& e) {
    EXPECT_TRUE(contains(e.what(), "the installed include directory")) << e.what();
  }
  fs::permissions(prefix / "include", include_perms, fs::perm_options::replace);
  const auto installed = delayspec::cli::model_headers(prefix / "lib");
  ASSERT_FALSE(installed.include_dirs.empty());
  EXPECT_EQ(installed.include_dirs.front(), (prefix / "include").string());
  // The headers' contents are in the cache key: another header, another entry.
  write(prefix / "include" / "delayspec" / "version.hpp", "#error planted, and changed\n");
  EXPECT_NE(delayspec::cli::model_headers(prefix / "lib").identity, installed.identity);
}

TEST_F(ModelCache, ACompilersGroupWritableObjectIsMadePrivateNotRefused) {
  // Under a umask of 002 the linker makes the object 0775, which the cache would then refuse as
  // writable by others; the cache clears those bits of what the compiler made for it.
  const fs::path cache = dir_ / "cache";
  const delayspec::cli::ModelCacheDir dir(cache);
  write(cache / "made.so", "object");
  fs::permissions(cache / "made.so", fs::perms::owner_all | fs::perms::group_all | fs::perms::others_read,
                  fs::perm_options::replace);
  EXPECT_THROW(dir.open_entry("made.so"), delayspec::BadInput);
  dir.make_private("made.so");
  EXPECT_EQ(fs::status(cache / "made.so").permissions(), fs::perms::owner_all);
  EXPECT_TRUE(static_cast<bool>(dir.open_entry("made.so")));
  // A link is left alone (and its target untouched).
  fs::create_symlink(cache / "made.so", cache / "link.so");
  fs::permissions(cache / "made.so", fs::perms::owner_all | fs::perms::group_write, fs::perm_options::replace);
  dir.make_private("link.so");
  EXPECT_EQ(fs::status(cache / "made.so").permissions(), fs::perms::owner_all | fs::perms::group_write);
}

// The leading multiplier of `scene` (as JSON text) from a new process of the program with the
// model cache `cache` (this process keeps what it loaded); `out` receives the output.
std::string leading_multiplier(const fs::path& scene, const fs::path& cache, const fs::path& out) {
  const std::string command = std::string(DELAYSPEC_CLI_PATH) + " floquet " + scene.string() +
                              " --json --set model_cache=" + cache.string() + " --set N=20 --set nev=1 > " +
                              out.string() + " 2>/dev/null";
  EXPECT_EQ(std::system(command.c_str()), 0) << read_text(out);
  const nlohmann::json j = nlohmann::json::parse(read_text(out), nullptr, false);
  return j.is_object() && j.contains("multipliers") ? j.at("multipliers").dump() : read_text(out);
}

// Issue 61 item 4: a cache entry's object is bound to its entry. Two models compiled into one
// cache, then their objects and checksum records swapped pair for pair (each pair valid on its
// own): model A run in a new process (this one keeps what it loaded) must not run B's code. It
// used to (exit 0, B's multipliers); now the record names its entry, the lookup finds another
// name, and each model is compiled again: its own multipliers.
TEST_F(ModelCache, AnotherEntrysObjectAndRecordAreNotLoadedAsThisOne) {
  const fs::path cache = dir_ / "cache";
  const fs::path scene_a = dir_ / "a.toml", scene_b = dir_ / "b.toml";
  write(scene_a, std::string("model = \"equations\"\n") + kEquations);
  std::string b = kEquations;
  b.replace(b.find("a*x + b*x_tau"), std::string("a*x + b*x_tau").size(), "a*x - b*x_tau");
  write(scene_b, "model = \"equations\"\n" + b);
  auto leading = [&](const fs::path& scene) { return leading_multiplier(scene, cache, dir_ / "out.json"); };
  const std::string a = leading(scene_a), b_values = leading(scene_b);
  ASSERT_NE(a, b_values) << "the two models must differ";
  std::vector<std::string> stems;
  for (const auto& e : fs::directory_iterator(cache))
    if (e.path().extension() == ".so") stems.push_back(e.path().stem().string());
  ASSERT_EQ(stems.size(), 2u);
  for (const char* ext : {".so", ".sum"}) {
    fs::rename(cache / (stems[0] + ext), dir_ / "swap");
    fs::rename(cache / (stems[1] + ext), cache / (stems[0] + ext));
    fs::rename(dir_ / "swap", cache / (stems[1] + ext));
  }
  EXPECT_EQ(leading(scene_a), a);
  EXPECT_EQ(leading(scene_b), b_values);
}

// Issue 61 item 4: a table's record (tx-HASH.table: the object's name, the table's text, the
// names and defaults) does not decide the parameters' defaults: they are read from the table text
// that is compared with the scene's. Editing the record's defaults line (a = -1 -> a = 5: an
// unstable model) changed the multipliers of the next run; now they are the first run's.
TEST_F(ModelCache, ATableRecordsDefaultsLineDoesNotChangeTheModel) {
  const fs::path cache = dir_ / "cache";
  const fs::path scene = dir_ / "a.toml";
  write(scene, std::string("model = \"equations\"\n") + kEquations);
  auto leading = [&] { return leading_multiplier(scene, cache, dir_ / "out.json"); };
  const std::string first = leading();
  fs::path record;
  for (const auto& e : fs::directory_iterator(cache))
    if (e.path().extension() == ".table") record = e.path();
  ASSERT_FALSE(record.empty());
  std::string text = read_text(record);
  const size_t at = text.find("\ndefaults -1 ");
  ASSERT_NE(at, std::string::npos) << text;
  text.replace(at, std::string("\ndefaults -1 ").size(), "\ndefaults 5 ");
  write(record, text);
  fs::permissions(record, fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_EQ(leading(), first);
}

}  // namespace
