// What a delayspec process loads. GiNaC, CLN and GMP (the symbolic front end of model =
// equations) and OpenMPI cost every process that links them 1.5 and 1.3 ms before main
// (docs/benchmarks.md, "Start-up"): they sit in the modules libdelayspec_equations and
// libdelayspec_mpi, which the program loads only for an [equations] table and under an MPI
// launcher (src/scene/loading/module_loader.hpp; tests/mpi_test.py checks the MPI side). Checked on the
// built program with the dynamic loader's own trace (LD_DEBUG=files lists every object it maps,
// at start and by dlopen), so a new link dependency or an eager load fails here; the equations
// run shows that the trace does see the module when it is loaded. The linear-algebra libraries
// (OpenBLAS, ARPACK, UMFPACK) are loaded by the library on first use (src/engine/linalg/linear_algebra.cpp):
// a run that needs no solver maps none of them, a run that does maps them.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "delayspec/errors.hpp"
#include "delayspec/version.hpp"
#include "delayspec_test_paths.hpp"
#include "scene/equations/equations_module_loader.hpp"
#include "scene/loading/module_loader.hpp"
#include "scene/loading/running_library.hpp"
#include "scene/problem/models_module_loader.hpp"
#include "scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;

struct Process {
  int status;
  std::string trace;  // the loader's trace and the program's stderr (stdout discarded)
};

// `prefix PROGRAM args` through the shell; stderr kept, stdout to `stdout_file`.
Process run_traced(const std::string& prefix, const std::string& program, const std::string& args,
                   const std::string& stdout_file = "/dev/null") {
  const std::string command = prefix + " '" + program + "' " + args + " 2>&1 >'" + stdout_file + "'";
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return {-1, ""};
  std::string text;
  char buffer[4096];
  for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) text.append(buffer, n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, text};
}

bool mentions(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The symbolic and MPI libraries and the modules that carry them.
void expect_no_module_libraries(const Process& p) {
  // The trace works: it names libdelayspec, which every command loads.
  ASSERT_TRUE(mentions(p.trace, "file=libdelayspec.so")) << p.trace.substr(0, 2000);
  for (const char* library : {"libginac", "libcln", "libgmp", "libdelayspec_equations", "libmpi", "libopen-rte",
                              "libopen-pal", "libhwloc", "libevent", "libdelayspec_mpi"})
    EXPECT_FALSE(mentions(p.trace, library)) << library << " loaded:\n" << p.trace.substr(0, 4000);
}

const std::string cache = std::string("--set model_cache=") + DELAYSPEC_TEST_MODEL_CACHE;

TEST(StartupLibraries, VersionLoadsNeitherGiNaCNorMPI) {
  const Process p = run_traced("LD_DEBUG=files", DELAYSPEC_CLI_PATH, "--version");
  EXPECT_EQ(p.status, 0) << p.trace;
  expect_no_module_libraries(p);
}

TEST(StartupLibraries, BuiltInModelLoadsNeitherGiNaCNorMPI) {
  const Process p = run_traced("LD_DEBUG=files", DELAYSPEC_CLI_PATH, "floquet --set model=impact --set N=20 --json");
  EXPECT_EQ(p.status, 0) << p.trace;
  expect_no_module_libraries(p);
  // The impact model's analyses are in the library: the other models' module stays unloaded.
  EXPECT_FALSE(mentions(p.trace, "libdelayspec_models")) << p.trace.substr(0, 4000);
}

// Another built-in model loads its analyses' module (src/modules/models/models_module.hpp), and
// only that one.
TEST(StartupLibraries, AnotherBuiltInModelLoadsTheModelsModuleOnly) {
  const Process p = run_traced("LD_DEBUG=files", DELAYSPEC_CLI_PATH, "floquet --set model=mathieu --set N=20 --json");
  EXPECT_EQ(p.status, 0) << p.trace;
  expect_no_module_libraries(p);
  EXPECT_TRUE(mentions(p.trace, "libdelayspec_models.so")) << p.trace.substr(0, 4000);
}

// The linear-algebra libraries, by the names the library asks for.
const std::vector<std::string> linear_algebra_libraries = {DELAYSPEC_BLAS_SONAME, DELAYSPEC_LAPACK_SONAME,
                                                           DELAYSPEC_ARPACK_SONAME, DELAYSPEC_UMFPACK_SONAME};

TEST(StartupLibraries, VersionAndLyapunovLoadNoLinearAlgebra) {
  for (const char* args : {"--version", "lyapunov --set model=mathieu --set N=50 --set periods=20 --json"}) {
    const Process p = run_traced("LD_DEBUG=files", DELAYSPEC_CLI_PATH, args);
    EXPECT_EQ(p.status, 0) << args << "\n" << p.trace;
    ASSERT_TRUE(mentions(p.trace, "file=libdelayspec.so")) << p.trace.substr(0, 2000);
    for (const std::string& library : linear_algebra_libraries)
      EXPECT_FALSE(mentions(p.trace, "file=" + library)) << args << ": " << library << " loaded";
  }
}

// Each solver's first use loads its library, and only that one (the trace names the file), and
// the run succeeds: dense LAPACK, the block Krylov-Schur (dgemm, dgees) and the Ritz vectors of
// Spectra's (dgemm) OpenBLAS, ARPACK its own, Newton's sparse LU UMFPACK.
TEST(StartupLibraries, EachSolverLoadsItsLibraryOnFirstUse) {
  const std::string openblas = DELAYSPEC_BLAS_SONAME, arpack = DELAYSPEC_ARPACK_SONAME,
                    umfpack = DELAYSPEC_UMFPACK_SONAME;
  struct Run {
    const char* args;
    std::vector<std::string> loaded, not_loaded;
  };
  const std::vector<Run> runs = {
      {"floquet --set model=impact --set N=20 --set solver=dense --json", {openblas}, {arpack, umfpack}},
      {"floquet --set model=impact --set N=600 --set solver=block --json", {openblas}, {arpack, umfpack}},
      {"floquet --set model=impact --set N=600 --set solver=arpack --json", {arpack}, {umfpack}},
      {"floquet --set model=impact --set N=600 --set solver=spectra --json", {openblas}, {arpack, umfpack}},
      {"floquet --set model=impact --set N=20 --set orbit=newton --set solver=spectra --json", {umfpack}, {arpack}}};
  for (const Run& run : runs) {
    const Process p = run_traced("LD_DEBUG=files", DELAYSPEC_CLI_PATH, run.args);
    EXPECT_EQ(p.status, 0) << run.args << "\n" << p.trace.substr(0, 4000);
    for (const std::string& library : run.loaded)
      EXPECT_TRUE(mentions(p.trace, "file=" + library)) << run.args << ": " << library << " not loaded";
    for (const std::string& library : run.not_loaded)
      EXPECT_FALSE(mentions(p.trace, "file=" + library)) << run.args << ": " << library << " loaded";
  }
}

// A library that cannot be loaded (here a file under UMFPACK's name that is not a shared object,
// found first through LD_LIBRARY_PATH): exit 2 naming it, not a crash, for the run that needs it
// (Newton's sparse LU); runs that do not need it are not affected.
TEST(StartupLibraries, AnUnloadableLinearAlgebraLibraryExits2NamingIt) {
  const fs::path dir = delayspec::testing::scratch_path("bad_umfpack");
  fs::create_directories(dir);
  {
    std::FILE* f = std::fopen((dir / DELAYSPEC_UMFPACK_SONAME).c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("not a shared object\n", f);
    std::fclose(f);
  }
  const std::string env = "LD_LIBRARY_PATH='" + dir.string() + "'";
  const Process p = run_traced(env, DELAYSPEC_CLI_PATH, "floquet --set model=impact --set N=20 --set orbit=newton");
  EXPECT_EQ(p.status, 2) << p.trace;
  EXPECT_TRUE(mentions(p.trace, std::string("cannot load ") + DELAYSPEC_UMFPACK_SONAME + " (SuiteSparse UMFPACK)"))
      << p.trace;
  for (const char* args : {"floquet --set model=impact --set N=20 --set orbit=shooting --set solver=dense",
                           "lyapunov --set model=mathieu --set N=50 --set periods=20"}) {
    const Process other = run_traced(env, DELAYSPEC_CLI_PATH, args);
    EXPECT_EQ(other.status, 0) << args << "\n" << other.trace;
  }
  fs::remove_all(dir);
}

std::string file_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The first run of an [equations] table reads it with the module (GiNaC); a later run of the same
// table finds the compiled model by the table's text (equation_plugin.hpp, TableRecord) and loads
// neither, with the same multipliers to the last bit. The table is the impact scene's with a
// default no earlier run has used (this process's id), overridden on the command line, so its
// first run here is a first run (the model itself, the same code, is compiled once per cache).
TEST(StartupLibraries, AnEquationsSceneLoadsGiNaCUntilItsModelIsCached) {
  const fs::path dir = delayspec::testing::scratch_path("cached_table");
  fs::create_directories(dir);
  std::string text = file_text(std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/equations_impact.toml");
  const std::string zeta = "zeta = 0.01,";
  ASSERT_NE(text.find(zeta), std::string::npos);
  text.replace(text.find(zeta), zeta.size(), "zeta = 0.01" + std::to_string(getpid()) + ",");
  const std::string scene = (dir / "impact.toml").string();
  std::ofstream(scene) << text;
  const std::string args = "floquet '" + scene + "' --set N=20 --set zeta=0.01 --json " + cache;
  std::string json[2];
  for (int run = 0; run < 2; ++run) {
    const std::string out = (dir / ("run" + std::to_string(run) + ".json")).string();
    const Process p = run_traced("LD_DEBUG=files", DELAYSPEC_CLI_PATH, args, out);
    ASSERT_EQ(p.status, 0) << p.trace;
    EXPECT_EQ(mentions(p.trace, "libdelayspec_equations.so"), run == 0) << run << p.trace.substr(0, 4000);
    EXPECT_EQ(mentions(p.trace, "libginac"), run == 0) << run << p.trace.substr(0, 4000);
    json[run] = file_text(out);
  }
  const auto multipliers = [](const std::string& text) {
    return nlohmann::json::parse(text).at("multipliers").dump();
  };
  EXPECT_EQ(multipliers(json[0]), multipliers(json[1]));
  fs::remove_all(dir);
}

// The program and its library copied to a directory without the module (LD_LIBRARY_PATH comes
// before the build tree's RUNPATH, so this libdelayspec is the one that runs): exit 2, naming
// the file it looked for, before any computation.
TEST(StartupLibraries, MissingModuleExits2NamingTheFile) {
  const fs::path dir = delayspec::testing::scratch_path("no_module");
  fs::create_directories(dir);
  // libdelayspec under each of its names (the soname the program asks for among them).
  const fs::path library = delayspec::cli::running_library();
  for (const fs::directory_entry& entry : fs::directory_iterator(library.parent_path()))
    if (entry.path().filename().string().rfind("libdelayspec.so", 0) == 0)
      fs::copy_file(library, dir / entry.path().filename());
  fs::copy_file(DELAYSPEC_CLI_PATH, dir / "delayspec");
  const std::string scene = std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/equations_impact.toml";
  const Process p = run_traced("LD_LIBRARY_PATH='" + dir.string() + "'", (dir / "delayspec").string(),
                               "floquet '" + scene + "' --set N=20 " + cache);
  EXPECT_EQ(p.status, 2) << p.trace;
  EXPECT_TRUE(mentions(p.trace, (dir / "libdelayspec_equations.so").string() + " (delayspec's symbolic front end)"))
      << p.trace;
  EXPECT_TRUE(mentions(p.trace, "it is missing")) << p.trace;
  // The same copy runs the impact model, whose analyses are in the library; the other built-in
  // models' are in libdelayspec_models, loaded on first use as the equations module: exit 2
  // naming the model and the file.
  const Process builtin = run_traced("LD_LIBRARY_PATH='" + dir.string() + "'", (dir / "delayspec").string(),
                                     "floquet --set model=impact --set N=20");
  EXPECT_EQ(builtin.status, 0) << builtin.trace;
  const Process linear = run_traced("LD_LIBRARY_PATH='" + dir.string() + "'", (dir / "delayspec").string(),
                                    "floquet --set model=linear --set N=20");
  EXPECT_EQ(linear.status, 2) << linear.trace;
  EXPECT_TRUE(mentions(linear.trace, "model = linear needs the module " + (dir / "libdelayspec_models.so").string()))
      << linear.trace;
  EXPECT_TRUE(mentions(linear.trace, "it is missing")) << linear.trace;
  fs::remove_all(dir);
}

const delayspec::cli::EquationsModule& load(const fs::path& file) {
  return delayspec::cli::load_module<delayspec::cli::EquationsModule>(file, delayspec::cli::equations_module_symbol,
                                                                      delayspec::cli::equations_module_description());
}

TEST(EquationsModuleLoader, RefusesAMissingFileAndAnObjectWithoutTheEntryPoint) {
  try {
    load("/nonexistent/libdelayspec_equations.so");
    ADD_FAILURE() << "no BadInput";
  } catch (const delayspec::BadInput& e) {
    EXPECT_TRUE(mentions(e.what(), "/nonexistent/libdelayspec_equations.so")) << e.what();
    EXPECT_TRUE(mentions(e.what(), "it is missing")) << e.what();
  }
  // libdelayspec is a shared object, but not the module.
  const fs::path library = delayspec::cli::running_library();
  try {
    load(library);
    ADD_FAILURE() << "no BadInput";
  } catch (const delayspec::BadInput& e) {
    EXPECT_TRUE(mentions(e.what(), library.string())) << e.what();
    EXPECT_TRUE(mentions(e.what(), "lacks `delayspec_equations_module`")) << e.what();
  }
}

TEST(ModelsModuleLoader, TheModuleBesideTheLibraryIsThisBuildsWithEveryEntry) {
  const delayspec::cli::ModelsModule& module = delayspec::cli::models_module("mathieu");
  EXPECT_EQ(std::string(module.version), std::string(DELAYSPEC_VERSION) + " " + DELAYSPEC_REVISION);
  EXPECT_NE(module.linear, nullptr);
  EXPECT_NE(module.mathieu, nullptr);
  EXPECT_NE(module.mackey_glass, nullptr);
  EXPECT_NE(module.milling, nullptr);
  EXPECT_NE(module.milling_variable_pitch, nullptr);
  // Through the table, the analyses of the model given (its dimension: linear 1, mathieu 2).
  EXPECT_EQ(module.linear(delayspec::LinearModel(delayspec::LinearParameters{}))->state_dimension(), 1);
  EXPECT_EQ(module.mathieu(delayspec::MathieuModel(delayspec::MathieuParameters{}))->state_dimension(), 2);
}

TEST(EquationsModuleLoader, TheModuleBesideTheLibraryIsThisBuildsAndReadsATable) {
  const delayspec::cli::EquationsModule& module = delayspec::cli::equations_module();
  EXPECT_EQ(std::string(module.version), std::string(DELAYSPEC_VERSION) + " " + DELAYSPEC_REVISION);
  const toml::table table = toml::parse(R"(state = ["x"]
parameters = { a = -1 }
period = "1"
delay = "1"
rhs = ["a*x + x_tau"]
history = { x = "1" }
)");
  const delayspec::cli::EquationModelSource source = module.generate(table, {"N"});
  EXPECT_EQ(source.state, std::vector<std::string>{"x"});
  EXPECT_EQ(source.parameters, std::vector<std::string>{"a"});
  EXPECT_EQ(source.parameter_defaults, std::vector<double>{-1});
  EXPECT_TRUE(mentions(source.code, "kFunctions"));
}

}  // namespace
