// model = equations end to end: a scene's [equations] table read by Config, printed as C++ by
// GiNaC, compiled, loaded, and run through the same analyses as the built-in models. Checked
// against what the code did not produce:
// - the paper's impact model and Mackey-Glass written as equations give the built-in models'
//   multipliers and Lyapunov exponents (the built-ins' derivatives are written by hand, the
//   equations' by GiNaC);
// - x' = a x + b x(t - tau) converges with order 2 to the exact (Lambert W) multipliers;
// - a d = 3 system coupled through commuting matrices, A = S diag(a) S^-1, B = S diag(b) S^-1,
//   whose multipliers are exactly those of the three scalar equations x' = a_i x + b_i x_tau
//   (Lambert W): order 2 against them;
// - a parameter given with --set reaches the compiled model without recompiling;
// - several delays (`delays`): x' = a x + b1 x(t - tau1) + b2 x(t - tau2) converges with order 2
//   to its exact characteristic roots (Newton in the test), a parameter a delay depends on
//   re-taps the compiled model, and `delay = E` is `delays = { tau = E }` bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <filesystem>

#include "scene/keys/config.hpp"
#include "delayspec_test_paths.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/lambert_w.hpp"
#include "scene/equations/equation_plugin.hpp"
#include "equation_scenes.hpp"
#include "scene/problem/problem.hpp"
#include "characteristic_roots.hpp"

namespace delayspec::cli {
namespace {

// The impact model of the paper as equations (the issue's scene; tau_over_T and k set per case).
const char* kImpactScene = R"scene(model = "equations"
[equations]
state = ["x", "v"]
parameters = { zeta = 0.01, e = 1.26, a = 0.7, beta = 28, omega = 0.802, k = 0.0 }
period = "2*pi/omega"
delay = "2*pi/omega"
rhs = ["v", "a*omega^2*sin(omega*t) + k*(v_tau - v) - 2*zeta*v - x"]
switch = "x - e"
rhs_switched = ["v", "a*omega^2*sin(omega*t) + k*(v_tau - v) - 2*zeta*v - x - beta*(x - e)"]
history = { x = 0.0, v = 0.0 }
)scene";

const char* kMackeyGlassScene = delayspec::testing::kMackeyGlassEquationsScene;

const char* kLinearScene = R"scene(model = "equations"
[equations]
state = ["x"]
parameters = { a = -1, b = 0.5 }
period = "1"
delay = "1"
rhs = ["a*x + b*x_tau"]
history = { x = 1 }
)scene";

// The build tree's test cache: each model compiles once for all test processes.
std::string cache_dir() { return DELAYSPEC_TEST_MODEL_CACHE; }

Problem problem_from(const std::string& scene, const std::vector<std::pair<std::string, std::string>>& sets) {
  Config config = Config::from_scene_text(scene, "test.toml");
  if (config.has("equations")) config.set("model_cache", cache_dir(), "test");
  for (const auto& [key, value] : sets) config.set(key, value, "test");
  return read_problem(config);
}

struct Spectrum {
  std::vector<std::complex<double>> multipliers;
  Eigen::VectorXd orbit;
};

Spectrum spectrum(const Problem& p, int nev) {
  const LinearisedOrbit at = p.analyses->linearised_orbit(p.map_settings(), OrbitSettings{});
  FloquetOptions options;
  options.nev = nev;
  return {floquet_multipliers(*at.monodromy, options).multipliers, at.orbit.history};
}

LyapunovResult exponents(const Problem& p, long periods) {
  LyapunovOptions options;
  options.exponents = 2;
  options.periods = periods;
  options.transient = 0;
  return p.analyses->lyapunov(p.map_settings(), options);
}

// Relative agreement of two runs of the same discrete problem whose only difference is how the
// field and its derivatives are evaluated (by hand against GiNaC's printed expressions): a few
// ulp per evaluation, amplified by the conditioning of the eigenproblem and of the orbit's
// Newton solve; 1e-12 leaves three to four orders of magnitude for that amplification.
constexpr double kSameProblem = 1e-12;

void expect_same_multipliers(const Spectrum& a, const Spectrum& b) {
  ASSERT_EQ(a.multipliers.size(), b.multipliers.size());
  for (size_t k = 0; k < a.multipliers.size(); ++k)
    EXPECT_LE(std::abs(a.multipliers[k] - b.multipliers[k]), kSameProblem * std::abs(b.multipliers[k]))
        << "mu_" << k + 1 << ": " << a.multipliers[k] << " vs " << b.multipliers[k];
  ASSERT_EQ(a.orbit.size(), b.orbit.size());
  EXPECT_LE((a.orbit - b.orbit).norm(), kSameProblem * b.orbit.norm());
}

void expect_same_exponents(const LyapunovResult& a, const LyapunovResult& b) {
  ASSERT_EQ(a.per_period.size(), b.per_period.size());
  const double scale = std::abs(b.per_period.front());
  for (size_t k = 0; k < a.per_period.size(); ++k)
    EXPECT_LE(std::abs(a.per_period[k] - b.per_period[k]), kSameProblem * scale)
        << "lambda_" << k + 1 << ": " << a.per_period[k] << " vs " << b.per_period[k];
}

TEST(EquationModels, ImpactAsEquationsEqualsTheBuiltInModel) {
  // tau = T with k = 0.55, and tau = T/2 with k = 0.03 (the issue's two cases), N = 800.
  for (const auto& [ratio, k] : {std::pair<const char*, const char*>{"1", "0.55"}, {"0.5", "0.03"}}) {
    SCOPED_TRACE(std::string("tau_over_T = ") + ratio + ", k = " + k);
    const std::vector<std::pair<std::string, std::string>> sets = {{"N", "800"}, {"k", k}, {"tau_over_T", ratio}};
    std::vector<std::pair<std::string, std::string>> builtin_sets = sets;
    builtin_sets.push_back({"model", "impact"});
    const Problem eq = problem_from(kImpactScene, sets), builtin = problem_from("", builtin_sets);
    EXPECT_TRUE(eq.analyses->switches_in_state());
    expect_same_multipliers(spectrum(eq, 6), spectrum(builtin, 6));
  }
  // Lyapunov exponents over 1000 periods from the same initial history (N = 200).
  const std::vector<std::pair<std::string, std::string>> sets = {{"N", "200"}, {"k", "0.55"}};
  expect_same_exponents(exponents(problem_from(kImpactScene, sets), 1000),
                        exponents(problem_from("model = \"impact\"", sets), 1000));
}

TEST(EquationModels, MackeyGlassAsEquationsEqualsTheBuiltInModel) {
  const std::vector<std::pair<std::string, std::string>> builtin_sets = {
      {"model", "mackey-glass"}, {"tau", "8"}, {"period", "8"}, {"N", "800"}};
  const Problem eq = problem_from(kMackeyGlassScene, {{"N", "800"}}), builtin = problem_from("", builtin_sets);
  EXPECT_FALSE(eq.analyses->is_linear());
  expect_same_multipliers(spectrum(eq, 4), spectrum(builtin, 4));
  Problem eq_short = eq, builtin_short = builtin;
  eq_short.N = builtin_short.N = 100;
  expect_same_exponents(exponents(eq_short, 1000), exponents(builtin_short, 1000));
}

// Observed order from errors at N, 2N, 4N: log2 of successive error ratios, averaged.
double observed_order(const std::vector<double>& errors) {
  return 0.5 * (std::log2(errors[0] / errors[1]) + std::log2(errors[1] / errors[2]));
}

// The error of the leading `count` multipliers (nearest exact one each) at N = 50, 100, 200.
std::vector<double> errors_against(const std::string& scene, const std::vector<std::complex<double>>& exact,
                                   int count) {
  std::vector<double> errors;
  for (int N : {50, 100, 200}) {
    const Problem p = problem_from(scene, {{"N", std::to_string(N)}});
    const auto mu = spectrum(p, count).multipliers;
    double worst = 0;
    for (int k = 0; k < count; ++k) {
      double nearest = INFINITY;
      for (auto e : exact) nearest = std::min(nearest, std::abs(mu[k] - e));
      worst = std::max(worst, nearest);
    }
    errors.push_back(worst);
  }
  return errors;
}

TEST(EquationModels, ScalarLinearEquationHasOrderTwoAgainstLambertW) {
  EXPECT_TRUE(problem_from(kLinearScene, {}).analyses->is_linear());
  const auto exact = linear_dde_multipliers(-1, 0.5, 1, 1, 6);
  const std::vector<double> e = errors_against(kLinearScene, exact, 3);
  // The trapezoid is second order (design.md); 0.05 is the issue's tolerance on the order.
  EXPECT_NEAR(observed_order(e), 2.0, 0.05) << e[0] << " " << e[1] << " " << e[2];
}

TEST(EquationModels, ThreeDimensionalCoupledSystemHasOrderTwoAgainstLambertW) {
  // S unit upper triangular, S^-1 = [[1, -1, 1], [0, 1, -1], [0, 0, 1]]; dyadic a_i, b_i make
  // A = S diag(a) S^-1 and B = S diag(b) S^-1 exact in the scene's decimal numbers.
  const double a[3] = {-1, -2, -0.5}, b[3] = {0.5, -0.25, 0.125};
  const Eigen::Matrix3d S = (Eigen::Matrix3d() << 1, 1, 0, 0, 1, 1, 0, 0, 1).finished();
  const Eigen::Matrix3d Si = S.inverse();
  const Eigen::Matrix3d A = S * Eigen::Vector3d(a[0], a[1], a[2]).asDiagonal() * Si;
  const Eigen::Matrix3d B = S * Eigen::Vector3d(b[0], b[1], b[2]).asDiagonal() * Si;
  const char* names[3] = {"x", "y", "z"};
  std::string rhs;
  for (int i = 0; i < 3; ++i) {
    std::string row;
    for (int j = 0; j < 3; ++j)
      row += " + (" + format_number(A(i, j)) + ")*" + names[j] + " + (" + format_number(B(i, j)) + ")*" + names[j] +
             "_tau";
    rhs += std::string(i ? ", " : "") + "\"" + row.substr(3) + "\"";
  }
  const std::string scene =
      "model = \"equations\"\n[equations]\nstate = [\"x\", \"y\", \"z\"]\nparameters = {}\n"
      "period = \"1\"\ndelay = \"1\"\nrhs = [" +
      rhs + "]\nhistory = { x = 1 }\n";
  const Problem p = problem_from(scene, {});
  EXPECT_EQ(p.state_dimension(), 3);
  EXPECT_TRUE(p.analyses->is_linear());
  std::vector<std::complex<double>> exact;
  for (int i = 0; i < 3; ++i)
    for (auto mu : linear_dde_multipliers(a[i], b[i], 1, 1, 6)) exact.push_back(mu);
  const std::vector<double> e = errors_against(scene, exact, 4);
  EXPECT_NEAR(observed_order(e), 2.0, 0.05) << e[0] << " " << e[1] << " " << e[2];
}

TEST(EquationModels, TimeWindowHasOrderTwoLocatedAndOneNotAgainstTheExactMultiplier) {
  // x' = a1 x inside the window sin(2 pi t) > c, x' = a2 x outside: a scalar linear ODE over one
  // period T = 1, so the multiplier is exp(a1 w + a2 (1 - w)) exactly, w the window's length
  // (pi - 2 asin c) / (2 pi). The window's ends are irrational: never on a grid node. The delay
  // term is absent (the delayed state is only carried), so mu_1 is the only non-zero multiplier.
  const char* scene = R"scene(model = "equations"
[equations]
state = ["x"]
parameters = { a1 = -2, a2 = 0.5, c = 0.3 }
period = "1"
delay = "1"
rhs = ["a2*x"]
switch = "sin(2*pi*t) - c"
rhs_switched = ["a1*x"]
history = { x = 1 }
)scene";
  const double w = (M_PI - 2 * std::asin(0.3)) / (2 * M_PI);
  const std::vector<std::complex<double>> exact = {std::exp(-2 * w + 0.5 * (1 - w))};
  EXPECT_TRUE(problem_from(scene, {}).analyses->switches_in_time());
  const std::vector<double> located = errors_against(scene, exact, 1);
  // The time-switched step is the trapezoid on each piece: second order (design.md 1.5b).
  EXPECT_NEAR(observed_order(located), 2.0, 0.1) << located[0] << " " << located[1] << " " << located[2];
  std::vector<double> plain;
  for (int N : {50, 100, 200}) {
    const auto mu = spectrum(problem_from(scene, {{"N", std::to_string(N)}, {"events", "off"}}), 1).multipliers;
    plain.push_back(std::abs(mu[0] - exact[0]));
  }
  // Each node in the branch of its own time: the jump costs O(h) (design.md 1.5b).
  EXPECT_LT(observed_order(plain), 1.5) << plain[0] << " " << plain[1] << " " << plain[2];
  EXPECT_GT(plain[2], 10 * located[2]);
}

TEST(EquationModels, AParameterChangeReachesTheModelWithoutRecompiling) {
  const Problem first = problem_from(kLinearScene, {});  // compiled or loaded once per process
  const long compiled = equation_plugin_compilations();
  const Problem other = problem_from(kLinearScene, {{"b", "0.25"}});
  EXPECT_EQ(equation_plugin_compilations(), compiled);
  const auto exact = linear_dde_multipliers(-1, 0.25, 1, 1, 2);
  const auto mu = spectrum(problem_from(kLinearScene, {{"b", "0.25"}, {"N", "400"}}), 1).multipliers;
  // Second order at N = 400 (h = 1/400): the error is about 1e-6 (the order test above).
  EXPECT_LE(std::abs(mu[0] - exact[0]), 1e-5);
  EXPECT_NE(first.analyses.get(), other.analyses.get());
}

const char* kTwoDelayScene = R"scene(model = "equations"
[equations]
state = ["x"]
parameters = { a = -1.0, b1 = 0.5, b2 = -0.7, s = 1 }
period = "1"
delays = { tau1 = "s", tau2 = "sqrt(2)" }
rhs = ["a*x + b1*x_tau1 + b2*x_tau2"]
history = { x = 1 }
)scene";

// The exact multipliers of kTwoDelayScene's equation at tau1 = s (T = 1).
std::vector<std::complex<double>> two_delay_exact(double s) {
  using cd = std::complex<double>;
  const double a = -1, b1 = 0.5, b2 = -0.7, tau2 = std::sqrt(2.0);
  const test::Characteristic ch{
      [=](cd l) { return l - a - b1 * std::exp(-l * s) - b2 * std::exp(-l * tau2); },
      [=](cd l) { return 1.0 + b1 * s * std::exp(-l * s) + b2 * tau2 * std::exp(-l * tau2); }};
  return test::exact_multipliers(ch, 1, -12, 60);
}

TEST(EquationModels, TwoDelaysHaveOrderTwoAgainstTheExactRoots) {
  const std::vector<std::complex<double>> exact = two_delay_exact(1);
  std::vector<double> errors;
  for (int N : {100, 200, 400, 800, 1600})
    errors.push_back(test::worst_distance(spectrum(problem_from(kTwoDelayScene, {{"N", std::to_string(N)}}), 6).multipliers, exact));
  // tau2 / h irrational: the interpolation weight changes with N, so the ratio of successive
  // errors wanders; over the whole range 2.00 +- 0.05 (the issue's tolerance).
  EXPECT_NEAR(std::log2(errors.front() / errors.back()) / 4, 2.0, 0.05) << errors.front() << " " << errors.back();
}

TEST(EquationModels, AParameterADelayDependsOnReTapsWithoutRecompiling) {
  problem_from(kTwoDelayScene, {});
  const long compiled = equation_plugin_compilations();
  const auto mu = spectrum(problem_from(kTwoDelayScene, {{"s", "0.5"}, {"N", "400"}}), 4).multipliers;
  EXPECT_EQ(equation_plugin_compilations(), compiled);
  // Second order at N = 400: ~1e-5 (the order test above has 4.5e-6 at tau1 = 1); the multipliers
  // at tau1 = 1 differ from these by more than 0.01.
  EXPECT_LE(test::worst_distance(mu, two_delay_exact(0.5)), 3e-5);
  EXPECT_GT(test::worst_distance(mu, two_delay_exact(1)), 1e-2);
}

// Equilibria (issue 35): an equation model without t is autonomous, its equilibrium's roots are
// the exact roots of its characteristic function (found here by Newton from a grid of starts,
// tests/support); a model with t in its right-hand side is not. The scenes are the ones compiled
// above: no compile of their own.
TEST(EquationModels, AutonomousEquationsHaveEquilibriaWithTheExactRoots) {
  using cd = std::complex<double>;
  EXPECT_FALSE(problem_from(kImpactScene, {}).analyses->is_autonomous());
  const Problem two = problem_from(kTwoDelayScene, {});
  ASSERT_TRUE(two.analyses->is_autonomous());
  EquilibriumOptions o;
  const EquilibriumResult r = two.analyses->equilibrium(Eigen::VectorXd::Constant(1, 0.3), o);
  EXPECT_LT(std::abs(r.state[0]), 1e-15);
  const double a = -1, b1 = 0.5, b2 = -0.7, tau2 = std::sqrt(2.0);
  const std::vector<cd> exact = test::exact_roots(
      {[=](cd l) { return l - a - b1 * std::exp(-l) - b2 * std::exp(-l * tau2); },
       [=](cd l) { return 1.0 + b1 * std::exp(-l) + b2 * tau2 * std::exp(-l * tau2); }},
      -12, 60);
  ASSERT_EQ(r.roots.size(), 6u);
  // Both are Newton on the same function to ~1e-15 relative: 1e-12 is the engine's stopping test.
  // (the nearest exact root of each: conjugates come in either order) and none of the six
  // rightmost exact roots is missed
  std::vector<cd> got;
  for (const CharacteristicRoot& root : r.roots) got.push_back(root.value);
  EXPECT_LT(test::worst_distance(got, exact), 1e-12);
  EXPECT_LT(test::worst_distance({exact.begin(), exact.begin() + 6}, got), 1e-12);

  // Mackey-Glass at x* = 1: x' = -gamma x + beta (2 - n) / 4 x(t - tau), Lambert W
  const Problem mg = problem_from(kMackeyGlassScene, {});
  const EquilibriumResult m = mg.analyses->equilibrium(Eigen::VectorXd::Constant(1, 1.1), o);
  EXPECT_NEAR(m.state[0], 1, 1e-14);
  const std::vector<cd> lambert = linear_dde_roots(-0.1, 0.2 * (2 - 10) / 4, 8, 12);
  for (size_t k = 0; k < 6; ++k) {
    double best = INFINITY;
    for (cd e : lambert) best = std::min(best, std::abs(m.roots[k].value - e));
    EXPECT_LT(best, 1e-12) << m.roots[k].value;
  }
}

// An orbit of unknown period (autonomous_orbit.hpp) of the equations and of the built-in model:
// the same discrete problem, evaluated by GiNaC's printed expressions or by hand (kSameProblem).
TEST(EquationModels, MackeyGlassOrbitOfUnknownPeriodEqualsTheBuiltInModels) {
  AutonomousOrbitOptions o;
  o.period_guess = 20;
  o.N = 100;
  const AutonomousLinearisedOrbit eq = problem_from(kMackeyGlassScene, {}).analyses->autonomous_orbit(o);
  const AutonomousLinearisedOrbit builtin =
      problem_from("", {{"model", "mackey-glass"}, {"tau", "8"}, {"period", "8"}}).analyses->autonomous_orbit(o);
  EXPECT_NEAR(eq.orbit.period, builtin.orbit.period, kSameProblem * builtin.orbit.period);
  EXPECT_LE((eq.orbit.sequence - builtin.orbit.sequence).norm(), kSameProblem * builtin.orbit.sequence.norm());
  EXPECT_GT(eq.orbit.period, 20);  // an orbit, not the equilibrium
}

TEST(EquationModels, OneDelayWrittenEitherWayIsBitIdentical) {
  std::string with_table = kLinearScene;
  with_table.replace(with_table.find("delay = \"1\""), 11, "delays = { tau = \"1\" }");
  const Spectrum a = spectrum(problem_from(kLinearScene, {{"N", "120"}}), 4),
                 b = spectrum(problem_from(with_table, {{"N", "120"}}), 4);
  ASSERT_EQ(a.multipliers.size(), b.multipliers.size());
  for (size_t k = 0; k < a.multipliers.size(); ++k) EXPECT_EQ(a.multipliers[k], b.multipliers[k]);
  const LyapunovResult la = exponents(problem_from(kLinearScene, {{"N", "50"}}), 200),
                       lb = exponents(problem_from(with_table, {{"N", "50"}}), 200);
  EXPECT_EQ(la.per_period, lb.per_period);
}

// Bad input names the item: each case's message contains `expected`. None of these compiles.
TEST(EquationModels, SeveralDelaysBadInputNamesTheDelay) {
  const auto message = [](const std::string& scene, const std::vector<std::pair<std::string, std::string>>& sets) {
    try {
      problem_from(scene, sets);
    } catch (const BadInput& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  const auto with = [](const std::string& from, const std::string& to) {
    std::string scene = kTwoDelayScene;
    scene.replace(scene.find(from), from.size(), to);
    return scene;
  };
  struct Case {
    std::string scene;
    std::vector<std::pair<std::string, std::string>> sets;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {with("x_tau2", "x_tau3"), {}, "did you mean `x_tau"},
      {kTwoDelayScene, {{"s", "0"}}, "`equations.delays.tau1` evaluates to 0"},
      {kTwoDelayScene, {{"s", "-2"}}, "`equations.delays.tau1` evaluates to -2"},
      {with("tau1 = \"s\"", "x = \"s\""), {}, "`equations.delays.x`: `x` is also a state"},
      {with("tau1 = \"s\"", "a = \"s\""), {}, "`equations.delays.a`: `a` is also a parameter"},
      {with("s = 1 }", "s = 1, x_tau1 = 2 }"), {}, "the delayed state `x_tau1` would be the parameter"},
      // states u, u_v and delays v_w, w: `u_v_w` is u delayed by v_w and u_v delayed by w (issue 61 item 5)
      {R"(model = "equations"
[equations]
state = ["u", "u_v"]
period = "1"
delays = { v_w = "1", w = "0.5" }
rhs = ["-u + 0.1*u_v_w", "-u_v"]
history = { u = 1, u_v = 0 }
)",
       {},
       "the delayed state `u_v_w` would mean both `u` delayed by `v_w` and `u_v` delayed by `w`"},
      {kTwoDelayScene, {{"s", "0.001"}, {"N", "100"}}, "`equations.delays.tau1` = 0.001 is shorter than one step"},
      {with("period = \"1\"", "period = \"1\"\ndelay = \"1\""), {}, "are both given"},
      {kTwoDelayScene, {{"tau_over_T", "1"}}, "this model has 2"},
      {with("delays = { tau1 = \"s\", tau2 = \"sqrt(2)\" }", "delays = 3"), {}, "must be a table of named delays"},
  };
  for (const Case& c : cases) EXPECT_NE(message(c.scene, c.sets).find(c.expected), std::string::npos) << message(c.scene, c.sets);
}

// A state switch with several delays (the event step carries the stacked taps): the impact model
// with its feedback gain split over two delays of the same length, k1 (v_tau1 - v) + k2 (v_tau2 -
// v), is the built-in model with k = k1 + k2 (the two taps are the same numbers), to rounding.
TEST(EquationModels, ImpactWithItsFeedbackSplitOverTwoEqualDelaysIsTheBuiltInModel) {
  std::string scene = kImpactScene;
  const auto replace_all = [&](const std::string& from, const std::string& to) {
    for (size_t at = scene.find(from); at != std::string::npos; at = scene.find(from, at + to.size()))
      scene.replace(at, from.size(), to);
  };
  replace_all("delay = \"2*pi/omega\"", "delays = { tau1 = \"2*pi/omega\", tau2 = \"2*pi/omega\" }");
  replace_all("k*(v_tau - v)", "k1*(v_tau1 - v) + k2*(v_tau2 - v)");
  replace_all("k = 0.0 }", "k1 = 0.0, k2 = 0.0 }");
  const Problem eq = problem_from(scene, {{"N", "800"}, {"k1", "0.3"}, {"k2", "0.25"}});
  // (grid = uniform: with two delays the grid stays uniform, grid.hpp; one delay would align it
  // with the orbit's contacts, contact_aligned_orbit.hpp, another discrete problem)
  const Problem builtin = problem_from(
      "", {{"model", "impact"}, {"N", "800"}, {"k", "0.55"}, {"tau_over_T", "1"}, {"grid", "uniform"}});
  EXPECT_TRUE(eq.analyses->switches_in_state());
  ASSERT_EQ(eq.analyses->delays().size(), 2u);
  expect_same_multipliers(spectrum(eq, 6), spectrum(builtin, 6));
}

// Issue 61 item 6: an autonomous model with one delay needs no `period` (it has no forcing; the
// period is then the delay, the sampling time of lyapunov and simulate), and its multipliers are
// the same as with `period` stated as the delay. A forced model without it is refused.
TEST(EquationModels, AnAutonomousModelWithOneDelayDefaultsThePeriodToTheDelay) {
  // kLinearScene with its period and delay 1.5 (not 1, so that a default that ignored the delay
  // would show); without its period it must be the same model
  std::string stated = kLinearScene;
  const std::string constants = "period = \"1\"\ndelay = \"1\"\n";
  stated.replace(stated.find(constants), constants.size(), "period = \"1.5\"\ndelay = \"1.5\"\n");
  std::string defaulted = stated;
  defaulted.erase(defaulted.find("period = \"1.5\"\n"), std::string("period = \"1.5\"\n").size());
  const Spectrum a = spectrum(problem_from(stated, {{"N", "30"}}), 3),
                 b = spectrum(problem_from(defaulted, {{"N", "30"}}), 3);
  ASSERT_EQ(a.multipliers.size(), b.multipliers.size());
  for (size_t k = 0; k < a.multipliers.size(); ++k) EXPECT_EQ(a.multipliers[k], b.multipliers[k]) << k;
  std::string forced = defaulted;
  forced.replace(forced.find("a*x + b*x_tau"), std::string("a*x + b*x_tau").size(), "a*x + b*x_tau + cos(t)");
  try {
    problem_from(forced, {});
    FAIL() << "a forced model without period was accepted";
  } catch (const BadInput& e) {
    EXPECT_NE(std::string(e.what()).find("`equations.period` is required: the right-hand side depends on t"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace delayspec::cli
