// model = equations through the command line: every command the issue names runs an equation
// model from a scene file (floquet, lyapunov, simulate, sweep, chart, basin, converge, bench,
// run); the numbers equal the built-in linear model's (the same discrete problem); the commands
// that only built-in models support refuse it with exit 2; bad equations exit 2 naming the item.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <cmath>

#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"
#include "delayspec/errors.hpp"
#include "delayspec_test_paths.hpp"

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::contains;
using delayspec::testing::fresh_dir;
using delayspec::testing::run;
using delayspec::testing::with_sets;

// x' = a x + b x(t - tau), the built-in linear model (a = -1, b = 0.5, tau = T = 1), with its
// initial history a parameter so that basin has two axes.
const char* kScene = R"scene(model = "equations"
[equations]
state = ["x"]
parameters = { a = -1, b = 0.5, x0 = 1 }
period = "1"
delay = "1"
rhs = ["a*x + b*x_tau"]
history = { x = "x0" }
)scene";

class EquationsCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fresh_dir("equations_cli");
    std::filesystem::create_directories(dir_);
    scene_ = (dir_ / "linear.toml").string();
    std::ofstream(scene_) << kScene;
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(dir_); }
  // COMMAND on the scene with the test's own model cache and `sets`.
  static CliResult command(const std::string& name, std::vector<std::string> sets, const std::string& scene = scene_) {
    sets.push_back(std::string("model_cache=") + DELAYSPEC_TEST_MODEL_CACHE);
    return run(with_sets({name, scene, "--json"}, sets));
  }
  static std::filesystem::path dir_;
  static std::string scene_;
};
std::filesystem::path EquationsCli::dir_;
std::string EquationsCli::scene_;

TEST_F(EquationsCli, FloquetEqualsTheBuiltInLinearModel) {
  const CliResult eq = command("floquet", {"N=50", "nev=3", "solver=dense"});
  ASSERT_EQ(eq.status, 0) << eq.err;
  const CliResult builtin = run(with_sets({"floquet", "--json"}, {"model=linear", "N=50", "nev=3", "solver=dense"}));
  ASSERT_EQ(builtin.status, 0) << builtin.err;
  const auto a = nlohmann::json::parse(eq.out), b = nlohmann::json::parse(builtin.out);
  EXPECT_EQ(a["model"], "equations");
  EXPECT_EQ(a["dimension"], b["dimension"]);
  for (size_t k = 0; k < 3; ++k)
    for (const char* part : {"re", "im"}) {
      // The same discrete problem, the same LAPACK call: a few ulp of the compiled coefficients.
      const double x = a["multipliers"][k][part], y = b["multipliers"][k][part];
      EXPECT_NEAR(x, y, 1e-13) << k << part;
    }
}

TEST_F(EquationsCli, EveryAnalysisCommandRunsIt) {
  struct Case {
    const char* command;
    std::vector<std::string> sets;
    const char* field;  // a field of the command's JSON that carries its result
  };
  const std::vector<Case> cases = {
      {"lyapunov", {"N=20", "periods=20", "exponents=1"}, "exponents_per_period"},
      {"simulate", {"N=20", "t_end=2"}, "samples"},
      {"sweep",
       {"N=20", "periods=10", "exponents=1", "sweep_key=b", "sweep_from=0", "sweep_to=0.5", "sweep_points=3"},
       "points"},
      {"chart",
       {"N=20", "chart_x=a", "chart_x_range=-2,-1", "chart_x_points=2", "chart_y=b", "chart_y_range=0,0.5",
        "chart_y_points=2"},
       "rows"},
      {"basin",
       {"N=20", "basin_x=x0", "basin_x_range=0,1", "basin_x_points=2", "basin_y=b", "basin_y_range=0,0.5",
        "basin_y_points=2", "basin_transient=5", "basin_max_period=2"},
       "rows"},
      {"converge", {"Ns=20,40,80", "nev=2"}, "rows"},
      {"bench", {"Ns=20,40", "nev=2", "solvers=arpack,dense-lapack"}, "rows"},
  };
  for (const auto& c : cases) {
    const CliResult r = command(c.command, c.sets);
    ASSERT_EQ(r.status, 0) << c.command << ": " << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_TRUE(j.contains(c.field)) << c.command << ": " << r.out.substr(0, 400);
  }
  // The chart's points carry the spectral radius of x' = a x + b x_tau: below 1 for b < -a.
  const auto chart = nlohmann::json::parse(command("chart", cases[3].sets).out);
  for (const auto& row : chart["rows"]) EXPECT_LT(row["spectral_radius"].get<double>(), 1) << row.dump();
}

TEST_F(EquationsCli, RunComputesTheScenesAnalyses) {
  const std::string scene = (dir_ / "run.toml").string();
  std::ofstream(scene) << "analyses = [\"floquet\", \"lyapunov\"]\nN = 20\nperiods = 10\n" << kScene;
  const std::filesystem::path out = dir_ / "run-out";
  const CliResult r = run({"run", scene, "--out", out.string(), "--quiet", "--set",
                           std::string("model_cache=") + DELAYSPEC_TEST_MODEL_CACHE});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(out / "floquet.json"));
  EXPECT_TRUE(std::filesystem::exists(out / "lyapunov.json"));
}

TEST_F(EquationsCli, ContinuationEqualsTheBuiltInLinearModelsBranch) {
  // x' = -x + b x(t - tau), tau = T = 2 pi / (3 sqrt 3): the Neimark-Sacker point at b = -2 exactly
  // (test_cli_continue.cpp), continued as equations and as the built-in model. The same discrete
  // problem at every point: the branches agree to the corrector's and the locator's tolerances
  // (1e-13 on the parameter here), far below 1e-9.
  const std::string scene = (dir_ / "continue.toml").string();
  std::ofstream(scene) << "model = \"equations\"\n[equations]\nstate = [\"x\"]\n"
                       << "parameters = { a = -1, b = -1.5 }\nperiod = \"2*pi/(3*sqrt(3))\"\n"
                       << "delay = \"2*pi/(3*sqrt(3))\"\nrhs = [\"a*x + b*x_tau\"]\n";
  const std::vector<std::string> sets = {"continue_key=b", "continue_from=-1.5", "continue_to=-2.5",
                                         "continue_Ns=50,100,200", "continue_tolerance=1e-13"};
  const CliResult eq = command("continue", sets, scene);
  ASSERT_EQ(eq.status, 0) << eq.err;
  std::vector<std::string> builtin_sets = sets;
  for (const char* s : {"model=linear", "a=-1"}) builtin_sets.push_back(s);
  builtin_sets.push_back("tau=" + delayspec::format_number(2 * std::numbers::pi / (3 * std::sqrt(3.0))));
  const CliResult builtin = run(with_sets({"continue", "--json"}, builtin_sets));
  ASSERT_EQ(builtin.status, 0) << builtin.err;
  const auto a = nlohmann::json::parse(eq.out), b = nlohmann::json::parse(builtin.out);
  EXPECT_EQ(a["model"], "equations");
  ASSERT_EQ(a["points"].size(), b["points"].size());
  for (size_t i = 0; i < a["points"].size(); ++i)
    EXPECT_NEAR(a["points"][i]["parameter"].get<double>(), b["points"][i]["parameter"].get<double>(), 1e-9) << i;
  ASSERT_EQ(a["bifurcations"].size(), 1u);
  ASSERT_EQ(b["bifurcations"].size(), 1u);
  const auto &ba = a["bifurcations"][0], &bb = b["bifurcations"][0];
  EXPECT_EQ(ba["type"], "neimark-sacker");
  EXPECT_EQ(bb["type"], "neimark-sacker");
  for (size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(ba["by_N"][i]["parameter"].get<double>(), bb["by_N"][i]["parameter"].get<double>(), 1e-9) << i;
  EXPECT_NEAR(ba["extrapolated"].get<double>(), bb["extrapolated"].get<double>(), 1e-9);
  // and both at the exact boundary within their error bar
  EXPECT_LE(std::abs(ba["extrapolated"].get<double>() + 2), ba["error_estimate"].get<double>());
}

TEST_F(EquationsCli, ContinuationOfTheImpactModelAsEquationsLocatesTheBuiltInGrazingAndPeriodDoubling) {
  // data/scenes/continue_grazing_e.toml (the impact orbit at tau = T, k = 0, continued in the gap
  // e) and the same system written as equations: a switch, events, grazing. The same discrete
  // problem: the located points agree to the locator's tolerance (1e-10 |to - from| = 1e-11), not
  // merely to the discretisation error (~1e-3 between N = 100 and 200).
  const std::string scene = (dir_ / "grazing.toml").string();
  std::ofstream(scene) << R"toml(model = "equations"
tau_over_T = 1
nev = 4
orbit = "newton"
[equations]
state = ["x", "v"]
parameters = { zeta = 0.01, e = 1.26, a = 0.7, beta = 28, omega = 0.802, k = 0 }
period = "2*pi/omega"
rhs = ["v", "a*omega^2*sin(omega*t) + k*(v_tau - v) - 2*zeta*v - x"]
switch = "x - e"
rhs_switched = ["v", "a*omega^2*sin(omega*t) + k*(v_tau - v) - 2*zeta*v - x - beta*(x - e)"]
)toml";
  const std::vector<std::string> sets = {"continue_key=e", "continue_from=1.3", "continue_to=1.2",
                                         "continue_Ns=50,100", "N=100"};
  const CliResult eq = command("continue", sets, scene);
  ASSERT_EQ(eq.status, 0) << eq.err;
  const CliResult builtin =
      run(with_sets({"continue", DELAYSPEC_SOURCE_DIR "/data/scenes/continue_grazing_e.toml", "--json"}, sets));
  ASSERT_EQ(builtin.status, 0) << builtin.err;
  const auto a = nlohmann::json::parse(eq.out), b = nlohmann::json::parse(builtin.out);
  ASSERT_EQ(a["bifurcations"].size(), b["bifurcations"].size());
  ASSERT_GE(a["bifurcations"].size(), 2u);  // grazing, then the period doubling
  EXPECT_EQ(a["bifurcations"][0]["type"], "grazing");
  for (size_t i = 0; i < a["bifurcations"].size(); ++i) {
    EXPECT_EQ(a["bifurcations"][i]["type"], b["bifurcations"][i]["type"]) << i;
    for (size_t n = 0; n < 2; ++n)
      EXPECT_NEAR(a["bifurcations"][i]["by_N"][n]["parameter"].get<double>(),
                  b["bifurcations"][i]["by_N"][n]["parameter"].get<double>(), 1e-9)
          << i << " " << n;
  }
}

TEST_F(EquationsCli, BadEquationsExitTwoNamingTheItem) {
  struct Case {
    std::string from, to, expected;
  };
  const std::vector<Case> cases = {
      {"rhs = [\"a*x + b*x_tau\"]", "rhs = [\"a*x + b*x_tua\"]", "x_tau"},           // unknown symbol: did you mean
      {"rhs = [\"a*x + b*x_tau\"]", "rhs = [\"a*x + (b*x_tau\"]", "equations.rhs"},  // parse error
      {"rhs = [\"a*x + b*x_tau\"]", "rhs = [\"a*x\", \"x\"]", "equations.rhs"},      // wrong length
      {"x0 = 1 }", "x0 = 1, nev = 2 }", "nev"},                                      // an engine key
  };
  for (const auto& c : cases) {
    std::string text = kScene;
    const auto at = text.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from;
    text.replace(at, c.from.size(), c.to);
    const std::string scene = (dir_ / "bad.toml").string();
    std::ofstream(scene) << text;
    const CliResult r = command("floquet", {"N=20"}, scene);
    EXPECT_EQ(r.status, 2) << c.to << ": " << r.err;
    EXPECT_TRUE(contains(r.err, c.expected)) << c.to << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

TEST_F(EquationsCli, NoCompilerExitsTwoNamingThePackage) {
  // A model no other test compiles (another history), so that this process must compile it.
  std::string text = kScene;
  text.replace(text.find("x0 = 1 }"), 8, "x0 = 1, unused_in_other_tests = 3 }");
  const std::string scene = (dir_ / "nocompiler.toml").string();
  std::ofstream(scene) << text;
  ::setenv("DELAYSPEC_CXX", "/nonexistent/c++", 1);
  const CliResult r = command("floquet", {"N=20"}, scene);
  ::unsetenv("DELAYSPEC_CXX");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "Debian package g++")) << r.err;
}

// A scene with `rhs` replaced (the table of kScene otherwise).
std::string scene_with(const std::filesystem::path& dir, const std::string& name, const std::string& from,
                       const std::string& to) {
  std::string text = kScene;
  text.replace(text.find(from), from.size(), to);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

TEST_F(EquationsCli, DeepOrHugeExpressionsAreBadInputNotACrash) {
  // 10 000 levels overflowed the stack in GiNaC's parser (exit 139; the Python interpreter died).
  const std::string deep = std::string(10000, '(') + "x" + std::string(10000, ')');
  std::string nested_calls;
  for (int i = 0; i < 10000; ++i) nested_calls += "sin(";
  nested_calls += "x";
  nested_calls.append(10000, ')');
  std::string long_sum = "x";
  for (int i = 0; i < 12000; ++i) long_sum += "+x";
  const struct {
    std::string rhs, expected;
  } cases[] = {{deep, "parentheses nested more than 100 deep"},
               {nested_calls, "parentheses nested more than 100 deep"},
               {long_sum, "more than 20000 numbers, names and operators"}};
  for (const auto& c : cases) {
    const std::string scene = scene_with(dir_, "deep.toml", "a*x + b*x_tau", c.rhs);
    const CliResult r = command("floquet", {"N=20"}, scene);
    EXPECT_EQ(r.status, 2) << c.expected;
    EXPECT_TRUE(contains(r.err, "`equations.rhs[1]`")) << r.err.substr(0, 300);
    EXPECT_TRUE(contains(r.err, c.expected)) << r.err.substr(0, 300);
    EXPECT_LT(r.err.size(), 600u) << "the message shows an excerpt of the expression, not all of it";
  }
  // Just inside the limit is fine as far as the reader goes (100 levels).
  const std::string hundred = std::string(100, '(') + "a*x" + std::string(100, ')') + " + b*x_tau";
  ::setenv("DELAYSPEC_CXX", "/nonexistent/c++", 1);  // the reader passes; the compile is not the point
  const CliResult ok = command("floquet", {"N=20"}, scene_with(dir_, "hundred.toml", "a*x + b*x_tau", hundred));
  ::unsetenv("DELAYSPEC_CXX");
  EXPECT_EQ(ok.status, 2) << ok.err;
  EXPECT_TRUE(contains(ok.err, "/nonexistent/c++")) << ok.err;
}

TEST_F(EquationsCli, ConstantsAndTheGridAreCheckedBeforeTheCompile) {
  // No compiler at all: each case must be refused for its own reason, so before any compile.
  ::setenv("DELAYSPEC_CXX", "/nonexistent/c++", 1);
  const struct {
    const char *from, *to;
    std::vector<std::string> sets;
    const char* expected;
  } cases[] = {
      {"delay = \"1\"", "delay = \"b - 0.5\"", {}, "`equations.delay` evaluates to 0"},
      {"period = \"1\"", "period = \"-b\"", {}, "`equations.period` evaluates to -0.5"},
      {"delay = \"1\"", "delay = \"1/(a + 1)\"", {}, "`equations.delay` evaluates to nan"},
      {"delay = \"1\"", "delay = \"b*1e-12\"", {}, "too many steps"},
      {"delay = \"1\"", "delay = \"b\"", {"b=0"}, "`equations.delay` evaluates to 0"},
      {"period = \"1\"", "period = \"1e-9\"", {}, "steps a history can hold"},
      {"history = { x = \"x0\" }", "history = { x = \"1/x0\" }", {"x0=0"}, "`equations.history.x`"},
  };
  for (const auto& c : cases) {
    const CliResult r = command("floquet", c.sets, scene_with(dir_, "constants.toml", c.from, c.to));
    EXPECT_EQ(r.status, 2) << c.to;
    EXPECT_TRUE(contains(r.err, c.expected)) << c.to << ": " << r.err;
    EXPECT_FALSE(contains(r.err, "/nonexistent/c++")) << c.to << ": " << r.err;
  }
  ::unsetenv("DELAYSPEC_CXX");
}

TEST_F(EquationsCli, ANonFiniteStepNamesTheTermAndThePoint) {
  // x^(1/3), with the equilibrium x = 1: from x = 0 the derivative 1/3 x^(-2/3) is infinite at
  // the first step (with the rhs a*x^(1/3) + b*x_tau, whose orbit is x = 0, this gave
  // "dense_eigenvalues: matrix has non-finite entries", exit 2); from x = -1 the power itself is
  // not real (C++: NaN, the first step's state).
  const std::string rhs = "a*(x^(1/3) - 1) + b*(x_tau - 1)";
  const std::string scene = scene_with(dir_, "cube_root.toml", "a*x + b*x_tau", rhs);
  const std::string term = "`equations.rhs[1] = \"" + rhs + "\"`";
  for (const auto& [name, sets] : std::vector<std::pair<std::string, std::vector<std::string>>>{
           {"floquet", {"N=20", "x0=0", "solver=dense"}},
           {"floquet", {"N=20", "x0=0"}},
           {"lyapunov", {"N=20", "x0=0", "periods=20", "transient=0"}}}) {
    const CliResult r = command(name, sets, scene);
    EXPECT_EQ(r.status, 3) << name << ": " << r.err;
    EXPECT_TRUE(contains(r.err, "at t = 0, x = 0, x_tau = 0")) << r.err;
    EXPECT_TRUE(contains(r.err, term)) << r.err;
    EXPECT_TRUE(contains(r.err, "its derivative by x, ")) << r.err;
    EXPECT_TRUE(contains(r.err, "is undefined")) << r.err;
  }
  for (const std::string name : {"floquet", "simulate"}) {
    const CliResult r = command(name, {"N=20", "x0=-1"}, scene);
    EXPECT_EQ(r.status, 3) << name << ": " << r.err;
    EXPECT_TRUE(contains(r.err, "at t = 0, x = -1, x_tau = -1")) << r.err;
    EXPECT_TRUE(contains(r.err, term + " is not a real number")) << r.err;
  }
  // From x = 1, the equilibrium: a finite step everywhere, the multipliers computed.
  const CliResult fine = command("floquet", {"N=20", "x0=1"}, scene);
  EXPECT_EQ(fine.status, 0) << fine.err;
}

TEST_F(EquationsCli, MissingTableIsBadInput) {
  const CliResult r = run({"floquet", "--set", "model=equations"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "[equations]")) << r.err;
}

}  // namespace
