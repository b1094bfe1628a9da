// The run-time compilation of a model (equation_plugin.hpp), on functions written here by hand in
// the form the equation printer emits: x' = a x + b x(t - tau), the built-in linear model. What
// is checked: the loaded analyses give the built-in model's multipliers; a second load is a
// cache hit (counted compilations, not a clock), and so is a later run of the same table found by
// the table's record; two threads loading a new model at once compile
// it once; a missing compiler, a compile error and an unwritable cache are BadInput.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "delayspec/builtin_analyses.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/prebuilt_shapes.hpp"
#include "scene/equations/equation_plugin.hpp"

namespace delayspec::cli {
namespace {

// What equation_model_source prints for state x, parameters (a, b), period 1, delay 1, rhs
// a*x + b*x_tau, history x = 1 (model_functions.hpp), with the shape `shape`.
std::string linear_code(const char* shape) {
  return std::string("constexpr int d = 1;\nconstexpr int parameter_count = 2;\n") +
         "constexpr delayspec::ModelShape kShape" + shape + ";\n" + R"(
static double period_of(const double*) { return 1.0; }
static void delays_of(const double*, double* taus) { taus[0] = 1.0; }
static void history_of(const double*, double* r) { r[0] = 1.0; }
static void f(int, double, const double* y, const double* z, const double* p, double* r) { r[0] = p[0] * y[0] + p[1] * z[0]; }
static void A(int, double, const double*, const double*, const double* p, double* r) { r[0] = p[0]; }
static void B(int, double, const double*, const double*, const double* p, double* r) { r[0] = p[1]; }
const delayspec::ModelFunctions kFunctions = {f, A, B, nullptr, nullptr, nullptr, nullptr, nullptr};
)";
}
// Linear and autonomous: a shape of prebuilt_shapes.hpp (the unit is the functions alone).
const ModelShape kPrebuilt{1, 1, ModelSwitching::none, true, true, true};
const std::string kLinearCode = linear_code("{1, 1, delayspec::ModelSwitching::none, true, true, true}");

// The table the code came from and what the scene layer keeps of it (here only its form matters).
const TableRecord kRecord{"state = [ 'x' ]\nrhs = [ 'a*x + b*x_tau' ]", "state x\n"};

class EquationPluginTest : public ::testing::Test {
 protected:
  void SetUp() override {
    cache_ = std::filesystem::temp_directory_path() / ("delayspec-plugin-test-" + std::to_string(::getpid()) + "-" +
                                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(cache_);
  }
  void TearDown() override { std::filesystem::remove_all(cache_); }
  std::filesystem::path cache_;
};

std::vector<std::complex<double>> leading(const ModelAnalyses& analyses, int N) {
  MapSettings map;
  map.N = N;
  const LinearisedOrbit at = analyses.linearised_orbit(map, OrbitSettings{});
  FloquetOptions options;
  options.nev = 4;
  options.solver = FloquetSolver::dense_lapack;
  return floquet_multipliers(*at.monodromy, options).multipliers;
}

TEST_F(EquationPluginTest, LoadedModelEqualsTheBuiltInASecondLoadIsACacheHitAndItsTableFindsIt) {
  EXPECT_FALSE(found_equation_plugin(kRecord.table_text, cache_));  // (an empty cache)
  const long before = equation_plugin_compilations();
  const EquationPlugin plugin = load_equation_plugin(kLinearCode, kPrebuilt, cache_, kRecord);
  EXPECT_EQ(equation_plugin_compilations(), before + 1);
  {  // a prebuilt shape: the unit is the functions, and the analyses come from libdelayspec_prebuilt
    std::filesystem::path unit = plugin.object;
    std::ifstream in(unit.replace_extension(".cpp"));
    const std::string source(std::istreambuf_iterator<char>(in), {});
    EXPECT_NE(source.find("delayspec::prebuilt_model_analyses(kShape"), std::string::npos) << source;
    EXPECT_EQ(source.find("model_analyses.hpp"), std::string::npos) << source;
  }
  const double p[2] = {-1.0, 0.5};
  EXPECT_EQ(plugin.period(p), 1.0);
  double tau = 0;
  plugin.delays(p, &tau);
  EXPECT_EQ(tau, 1.0);
  double y0 = 0;
  plugin.history(p, &y0);
  EXPECT_EQ(y0, 1.0);
  const std::unique_ptr<ModelAnalyses> loaded(plugin.analyses(p, &tau, 1.0, &y0));
  EXPECT_EQ(loaded->state_dimension(), 1);
  EXPECT_TRUE(loaded->is_linear());
  LinearParameters lp;
  lp.a = -1;
  lp.b = 0.5;
  const auto builtin = builtin_analyses(LinearModel(lp));
  const auto a = leading(*loaded, 64), b = leading(*builtin, 64);
  ASSERT_EQ(a.size(), b.size());
  // The same arithmetic in the same order: the two monodromies are the same matrix, and LAPACK
  // gives the same eigenvalues to rounding (1e-14 relative allows for a different code path of
  // the compiled expressions, a few ulp per entry).
  for (size_t k = 0; k < a.size(); ++k) EXPECT_LE(std::abs(a[k] - b[k]), 1e-14 * std::abs(b[0])) << k;

  const EquationPlugin again = load_equation_plugin(kLinearCode, kPrebuilt, cache_, kRecord);
  EXPECT_EQ(equation_plugin_compilations(), before + 1);  // the cached object, not a compilation
  EXPECT_EQ(again.object, plugin.object);

  // The table's record finds the object without the code (found_equation_plugin); another table,
  // a record cut short and an object changed after its checksum was recorded find nothing (the
  // caller then reads the table and compiles or loads by the code, as without a record). In this
  // test, not its own: a test compiles a model for seconds.
  const std::optional<FoundPlugin> hit = found_equation_plugin(kRecord.table_text, cache_);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->plugin.object, plugin.object);
  EXPECT_EQ(hit->names, kRecord.names);
  EXPECT_EQ(hit->plugin.period(p), 1.0);
  EXPECT_FALSE(found_equation_plugin(kRecord.table_text + " ", cache_));

  std::vector<std::filesystem::path> records;
  for (const auto& entry : std::filesystem::directory_iterator(cache_))
    if (entry.path().extension() == ".table") records.push_back(entry.path());
  ASSERT_EQ(records.size(), 1u);
  const auto contents = [](const std::filesystem::path& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string whole = contents(records[0]);
  std::ofstream(records[0], std::ios::trunc) << whole.substr(0, whole.size() / 2);
  EXPECT_FALSE(found_equation_plugin(kRecord.table_text, cache_));
  std::ofstream(records[0], std::ios::trunc) << whole;
  ASSERT_TRUE(found_equation_plugin(kRecord.table_text, cache_));
  std::ofstream(plugin.object, std::ios::app) << '\0';  // the object's bytes no longer its checksum's
  EXPECT_FALSE(found_equation_plugin(kRecord.table_text, cache_));
}

TEST_F(EquationPluginTest, AShapeThatIsNotPrebuiltCompilesWholeAndGivesTheSameMultipliers) {
  // The same model declared forced (autonomous = false): no prebuilt shape, so its unit
  // instantiates the analyses of FunctionModel itself. The multipliers are those of the prebuilt
  // shape's analyses to the last bit (the same template over the same functions) and the
  // built-in model's to rounding (see above).
  const ModelShape forced{1, 1, ModelSwitching::none, false, true, true};
  ASSERT_FALSE(is_prebuilt_shape(forced));
  const EquationPlugin whole =
      load_equation_plugin(linear_code("{1, 1, delayspec::ModelSwitching::none, false, true, true}"), forced, cache_, kRecord);
  const EquationPlugin prebuilt = load_equation_plugin(kLinearCode, kPrebuilt, cache_, kRecord);
  const double p[2] = {-1.0, 0.5}, y0 = 1, tau = 1;
  const std::unique_ptr<ModelAnalyses> a(whole.analyses(p, &tau, 1, &y0)), b(prebuilt.analyses(p, &tau, 1, &y0));
  EXPECT_FALSE(a->is_autonomous());
  EXPECT_TRUE(b->is_autonomous());
  const auto from_whole = leading(*a, 64), from_prebuilt = leading(*b, 64);
  ASSERT_EQ(from_whole.size(), from_prebuilt.size());
  for (size_t k = 0; k < from_whole.size(); ++k) EXPECT_EQ(from_whole[k], from_prebuilt[k]) << k;
  LinearParameters lp;
  lp.a = -1;
  lp.b = 0.5;
  const auto builtin = leading(*builtin_analyses(LinearModel(lp)), 64);
  for (size_t k = 0; k < builtin.size(); ++k)
    EXPECT_LE(std::abs(from_whole[k] - builtin[k]), 1e-14 * std::abs(builtin[0])) << k;
}

// The library's lookup (model_functions.hpp): the analyses for each listed shape, null for any
// other (the loader then says to rebuild the library, equation_model.cpp).
void linear_f(int, double, const double* y, const double* z, const double* p, double* r) { r[0] = p[0] * y[0] + p[1] * z[0]; }
void linear_A(int, double, const double*, const double*, const double* p, double* r) { r[0] = p[0]; }
void linear_B(int, double, const double*, const double*, const double* p, double* r) { r[0] = p[1]; }
// A switch x - 1 (a model of a state-switch shape reads its gradient and H(0) when made).
double switch_H(const double* y, const double*) { return y[0] - 1; }
void switch_grad_H(const double*, const double*, double* r) { r[0] = 1; }

TEST(PrebuiltModels, EveryListedShapeAndNoOtherHasAnalyses) {
  ModelFunctions functions{linear_f, linear_A, linear_B};
  functions.H = switch_H;
  functions.grad_H = switch_grad_H;
  const double p[2] = {-1.0, 0.5}, tau = 1, y0 = 1;
  const ModelValues values{p, 2, &tau, 1.0, &y0};
  const std::unique_ptr<ModelAnalyses> linear(prebuilt_model_analyses(kPrebuilt, functions, values));
  ASSERT_TRUE(linear);
  EXPECT_EQ(linear->state_dimension(), 1);
  EXPECT_TRUE(linear->is_linear());
  EXPECT_TRUE(linear->is_autonomous());
  EXPECT_EQ(linear->tau(), 1.0);
  for (const ModelShape& shape : kPrebuiltShapes) {  // each shape's own analyses (not evaluated)
    std::vector<double> taus(static_cast<size_t>(shape.delay_count), 1.0), history(static_cast<size_t>(shape.d), 0.0);
    const std::unique_ptr<ModelAnalyses> a(prebuilt_model_analyses(shape, functions, {p, 2, taus.data(), 1.0, history.data()}));
    ASSERT_TRUE(a) << shape.d;
    EXPECT_EQ(a->state_dimension(), shape.d);
    EXPECT_EQ(a->delays().size(), static_cast<size_t>(shape.delay_count));
    EXPECT_EQ(a->switches_in_state(), shape.switching == ModelSwitching::state);
    EXPECT_EQ(a->switches_in_time(), shape.switching == ModelSwitching::time);
    EXPECT_EQ(a->is_autonomous(), shape.autonomous);
    EXPECT_EQ(a->is_linear(), shape.is_linear);
  }
  const ModelShape forced{1, 1, ModelSwitching::none, false, true, true};
  EXPECT_EQ(prebuilt_model_analyses(forced, functions, values), nullptr);
  EXPECT_EQ(prebuilt_model_analyses({7, 1, ModelSwitching::none, false, false, false}, functions, values), nullptr);
}

TEST_F(EquationPluginTest, ConcurrentFirstLoadsCompileOnce) {
  // Another source (a comment differs) than the other tests: a new cache entry.
  const std::string code = std::string("// concurrent\n") + kLinearCode;
  const long before = equation_plugin_compilations();
  EquationPlugin first, second;
  std::thread t1([&] { first = load_equation_plugin(code, kPrebuilt, cache_, kRecord); });
  std::thread t2([&] { second = load_equation_plugin(code, kPrebuilt, cache_, kRecord); });
  t1.join();
  t2.join();
  EXPECT_EQ(equation_plugin_compilations(), before + 1);
  EXPECT_EQ(first.object, second.object);
  const double p[2] = {-1.0, 0.5}, y0 = 1, tau = 1;
  EXPECT_EQ(std::unique_ptr<ModelAnalyses>(second.analyses(p, &tau, 1, &y0))->state_dimension(), 1);
}

TEST_F(EquationPluginTest, TwoModelsInOneProcessAreTwoObjects) {
  // Objects are opened through the descriptor whose bytes were checked (/proc/self/fd/N); the
  // dynamic loader matches objects by that name, so a second model must not reuse the first's N
  // and get the first model's code (it did, with the descriptor closed after loading).
  std::string other = kLinearCode;
  const std::string period = "static double period_of(const double*) { return 1.0; }";
  ASSERT_NE(other.find(period), std::string::npos);
  other.replace(other.find(period), period.size(), "static double period_of(const double*) { return 2.0; }");
  const EquationPlugin first = load_equation_plugin(kLinearCode, kPrebuilt, cache_, kRecord);
  const EquationPlugin second = load_equation_plugin(other, kPrebuilt, cache_, kRecord);
  const double p[2] = {-1.0, 0.5};
  EXPECT_EQ(first.period(p), 1.0);
  EXPECT_EQ(second.period(p), 2.0);
  EXPECT_NE(first.object, second.object);
}

TEST_F(EquationPluginTest, ACompileErrorIsBadInputWithTheCompilersFirstLines) {
  try {
    load_equation_plugin("constexpr int d = 1; this is not C++;", kPrebuilt, cache_, kRecord);
    FAIL() << "no BadInput";
  } catch (const BadInput& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("did not compile"), std::string::npos) << what;
    EXPECT_NE(what.find("error"), std::string::npos) << what;  // the compiler's own line
  }
}

TEST_F(EquationPluginTest, NoCompilerIsBadInputNamingThePackage) {
  const char* old = std::getenv("DELAYSPEC_CXX");
  const std::string saved = old ? old : "";
  ::setenv("DELAYSPEC_CXX", "/nonexistent/g++", 1);
  try {
    load_equation_plugin(kLinearCode, kPrebuilt, cache_, kRecord);
    ADD_FAILURE() << "no BadInput";
  } catch (const BadInput& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("/nonexistent/g++"), std::string::npos) << what;
    EXPECT_NE(what.find("Debian package g++"), std::string::npos) << what;
  }
  if (old) ::setenv("DELAYSPEC_CXX", saved.c_str(), 1);
  else ::unsetenv("DELAYSPEC_CXX");
}

TEST_F(EquationPluginTest, AnUnusableCacheDirectoryIsBadInput) {
  std::filesystem::create_directories(cache_);
  const std::filesystem::path file = cache_ / "a-file";
  { std::ofstream(file) << "x"; }
  EXPECT_THROW(load_equation_plugin(kLinearCode, kPrebuilt, file / "cache", kRecord), BadInput);
}

}  // namespace
}  // namespace delayspec::cli
