// The symbolic front end of equation models (src/modules/equations): the scene's [equations] table
// checked, differentiated with GiNaC and printed as C++. What the compiled code computes is
// tested end to end with the plugin loader; here: every bad input names its item, the model
// flags, the continuity check of a state switch, nothing of the scene reaches the code as text,
// and GiNaC's derivatives against finite differences of f.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <toml++/toml.h>

#include "delayspec/errors.hpp"
#include "delayspec/prebuilt_shapes.hpp"
#include "text_support.hpp"
#include "delayspec_test_paths.hpp"
#include "modules/equations/equation_model_source.hpp"
#include "modules/equations/equation_model_symbolic.hpp"

namespace {

using delayspec::BadInput;
using delayspec::cli::analyse_equations;
using delayspec::cli::EquationModelSource;
using delayspec::cli::generate_equation_model;
using delayspec::cli::SymbolicEquationModel;
using delayspec::cli::terms_not_finite;

const std::vector<std::string> kEngineKeys = {"N", "nev", "seed", "solver", "tau_over_T"};

using delayspec::testing::contains;

// The impact model as a table (data/scenes/equations_impact.toml without the history).
toml::table impact_table() {
  return toml::table{
      {"state", toml::array{"x", "v"}},
      {"parameters", toml::table{{"zeta", 0.01}, {"e", 1.26}, {"a", 0.7}, {"beta", 28}, {"omega", 0.802}, {"k", 0.55}}},
      {"period", "2*pi/omega"},
      {"delay", "2*pi/omega"},
      {"rhs", toml::array{"v", "a*omega^2*sin(omega*t) + k*(v_tau - v) - 2*zeta*v - x"}},
      {"switch", "x - e"},
      {"rhs_switched", toml::array{"v", "a*omega^2*sin(omega*t) + k*(v_tau - v) - 2*zeta*v - x - beta*(x - e)"}},
  };
}

// A one-dimensional model x' = rhs with parameters a = -1, b = 0.5, period 2 and delay 1.
toml::table scalar_table(const std::string& rhs) {
  return toml::table{{"state", toml::array{"x"}},
                     {"parameters", toml::table{{"a", -1.0}, {"b", 0.5}}},
                     {"period", "2"},
                     {"delay", "1"},
                     {"rhs", toml::array{rhs}}};
}

toml::table scene_equations(const std::string& file) {
  toml::table scene = toml::parse_file(std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/" + file);
  return *scene["equations"].as_table();
}

// The BadInput message of generating `table`, or "" if it is accepted.
std::string error_of(const toml::table& table) {
  try {
    generate_equation_model(table, kEngineKeys);
  } catch (const BadInput& e) {
    return e.what();
  }
  return "";
}

double to_double(const GiNaC::ex& e) { return GiNaC::ex_to<GiNaC::numeric>(GiNaC::evalf(e)).to_double(); }

// ---- the shipped scenes and the flags ----

TEST(EquationModelSource, ImpactSceneIsAStateSwitchWithContinuousFields) {
  const EquationModelSource s = generate_equation_model(scene_equations("equations_impact.toml"), kEngineKeys);
  EXPECT_EQ(s.state, (std::vector<std::string>{"x", "v"}));
  // sorted by name (toml++ keeps tables sorted): the order of p[k] in the code
  EXPECT_EQ(s.parameters, (std::vector<std::string>{"a", "beta", "e", "k", "omega", "zeta"}));
  EXPECT_EQ(s.parameter_defaults, (std::vector<double>{0.7, 28, 1.26, 0.55, 0.802, 0.01}));
  EXPECT_TRUE(s.shape.switching == delayspec::ModelSwitching::state);
  EXPECT_FALSE(s.shape.switching == delayspec::ModelSwitching::time);
  EXPECT_EQ(s.shape, (delayspec::ModelShape{2, 1, delayspec::ModelSwitching::state, false, true, false}));
  for (const char* line :
       {"constexpr int d = 2;", "constexpr int parameter_count = 6;",
        "constexpr delayspec::ModelShape kShape{d, 1, delayspec::ModelSwitching::state, false, true, false};",
        "static double H(", "static void grad_H(", "static void f_t(", "static void f_tt(", "static void A(",
        "static void B(", "kFunctions = {f, A, B, f_t, f_tt, H, grad_H, nullptr};"})
    EXPECT_TRUE(contains(s.code, line)) << line << "\n" << s.code;
  EXPECT_FALSE(contains(s.code, "switch_value"));
  // A column by column: row 1 of the contact field is -1 - beta in column 0 (index 1 + 2 * 0)
  // and -2 zeta - k in column 1 (index 3); A(0, 1) = 1 is index 2.
  EXPECT_TRUE(contains(s.code, "    r[2] = 1.0;")) << s.code;
}

TEST(EquationModelSource, TwoOscillatorSceneIsSmoothOfDimensionFour) {
  const EquationModelSource s = generate_equation_model(scene_equations("equations_two_oscillators.toml"), kEngineKeys);
  EXPECT_EQ(s.state.size(), 4u);
  EXPECT_FALSE(s.shape.switching == delayspec::ModelSwitching::state);
  EXPECT_FALSE(s.shape.switching == delayspec::ModelSwitching::time);
  EXPECT_EQ(s.shape, (delayspec::ModelShape{4, 1, delayspec::ModelSwitching::none, false, false, false}));
  EXPECT_TRUE(contains(s.code, "constexpr int d = 4;"));
  EXPECT_FALSE(contains(s.code, "double H("));
  EXPECT_TRUE(contains(s.code, "kFunctions = {f, A, B, nullptr, nullptr, nullptr, nullptr, nullptr};")) << s.code;
}

TEST(EquationModelSource, EveryShippedEquationSceneHasAPrebuiltShape) {
  // docs/models.md: the shapes of the shipped scenes are prebuilt, so each of them compiles only
  // its functions (under a second). A new scene of another shape fails here: add its shape to
  // prebuilt_shapes.hpp (or say in the docs why not).
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes")) {
    if (entry.path().extension() != ".toml") continue;
    const toml::table scene = toml::parse_file(entry.path().string());
    if (scene["model"].value_or(std::string()) != "equations") continue;
    ++scenes;
    const EquationModelSource s = generate_equation_model(*scene["equations"].as_table(), kEngineKeys);
    EXPECT_TRUE(delayspec::is_prebuilt_shape(s.shape))
        << entry.path().filename() << ": d " << s.shape.d << ", " << s.shape.delay_count << " delay(s), switch "
        << static_cast<int>(s.shape.switching) << ", autonomous " << s.shape.autonomous << ", affine "
        << s.shape.affine_in_state << ", linear " << s.shape.is_linear;
  }
  EXPECT_EQ(scenes, 6);  // equations_impact, _two_delays, _two_oscillators, equilibrium_neuron_ring, pyragas_oscillator,
                        // wright_generalised_hopf
}

TEST(EquationModelSource, FlagsFollowTheSecondDerivatives) {
  struct Case {
    const char* rhs;
    bool affine_in_state, is_linear;
  };
  for (const Case& c : {Case{"a*x + b*x_tau", true, true},                  // linear
                        Case{"a*x + b*x_tau + sin(pi*t)", true, true},      // forcing g(t) allowed
                        Case{"a*x*cos(t) + b*x_tau", true, true},           // time-periodic coefficients
                        Case{"b*x_tau/(1 + x_tau^10) + a*x", true, false},  // Mackey-Glass: nonlinear in z only
                        Case{"x*x_tau", true, false},                       // affine in y for fixed z, not jointly
                        Case{"a*x^2 + b*x_tau", false, false}, Case{"sin(x)", false, false},
                        Case{"(x + 1)^2 - x^2 - 2*x", true, true}}) {  // cancels to 1
    const SymbolicEquationModel m = analyse_equations(scalar_table(c.rhs), kEngineKeys);
    EXPECT_EQ(m.affine_in_state, c.affine_in_state) << c.rhs;
    EXPECT_EQ(m.is_linear, c.is_linear) << c.rhs;
  }
}

TEST(EquationModelSource, NamesOfGiNaCFunctionsAreOrdinaryNames) {
  // GiNaC's parser knows beta, zeta, psi, tgamma, H, ... as functions and I, Pi as constants; a
  // scene's names reach it only as generated keys, so these are plain parameters.
  toml::table table{
      {"state", toml::array{"H", "G"}},
      {"parameters", toml::table{{"beta", 2}, {"zeta", 3}, {"psi", 5}, {"tgamma", 7}, {"Li", 11}, {"lst", 13}}},
      {"period", "beta*zeta"},
      {"rhs", toml::array{"psi*H + tgamma*G_tau", "Li*G - lst*H_tau"}}};
  const SymbolicEquationModel m = analyse_equations(table, kEngineKeys);
  EXPECT_TRUE((m.period - m.p[1] * m.p[5]).is_zero()) << m.period;  // sorted: Li beta lst psi tgamma zeta
  EXPECT_TRUE((m.fields[0].f[0] - (m.p[3] * m.y[0] + m.p[4] * m.z[1])).is_zero()) << m.fields[0].f[0];
  EXPECT_TRUE((m.fields[0].f[1] - (m.p[0] * m.y[1] - m.p[2] * m.z[0])).is_zero()) << m.fields[0].f[1];
}

TEST(EquationModelSource, NumbersArePrintedExactly) {
  // 0.1 is 1/10: printed as the ratio of two exact doubles, so the division gives the double
  // nearest to 0.1 (what the literal 0.1 gives); a 20-digit decimal is not a ratio of doubles
  // and is printed as 17 significant digits.
  toml::table table = scalar_table("0.1*x + 0.12345678901234567891*x_tau - 3");
  const std::string code = generate_equation_model(table, kEngineKeys).code;
  EXPECT_TRUE(contains(code, "(1.0/10.0)*y[0]")) << code;
  EXPECT_TRUE(contains(code, "0.12345678901234568*z[0]")) << code;
  EXPECT_TRUE(contains(code, " - 3.0")) << code;
}

TEST(EquationModelSource, AStateSwitchIsNeverLinearAndATimeSwitchMayBe) {
  const SymbolicEquationModel impact = analyse_equations(impact_table(), kEngineKeys);
  EXPECT_TRUE(impact.affine_in_state);
  EXPECT_FALSE(impact.is_linear);  // the monodromy depends on the orbit through the contacts

  toml::table window = scalar_table("a*x + b*x_tau");
  window.insert_or_assign("switch", "sin(pi*t)");               // on for half the period
  window.insert_or_assign("rhs_switched", toml::array{"a*x"});  // discontinuous in t: allowed
  const EquationModelSource s = generate_equation_model(window, kEngineKeys);
  EXPECT_TRUE(s.shape.switching == delayspec::ModelSwitching::time);
  EXPECT_FALSE(s.shape.switching == delayspec::ModelSwitching::state);
  EXPECT_EQ(s.shape, (delayspec::ModelShape{1, 1, delayspec::ModelSwitching::time, false, true, true}));
  for (const char* line : {"static double switch_value(", "nullptr, nullptr, nullptr, nullptr, switch_value};"})
    EXPECT_TRUE(contains(s.code, line)) << line << "\n" << s.code;
  EXPECT_FALSE(contains(s.code, "grad_H"));
}

TEST(EquationModelSource, NoParametersGiveAnEmptyArray) {
  toml::table table{{"state", toml::array{"x"}}, {"period", "2*pi"}, {"rhs", toml::array{"-x + x_tau/2"}}};
  const EquationModelSource s = generate_equation_model(table, kEngineKeys);
  EXPECT_TRUE(s.parameters.empty());
  EXPECT_TRUE(contains(s.code, "constexpr int parameter_count = 0;"));
  // delay defaults to the period
  const SymbolicEquationModel m = analyse_equations(table, kEngineKeys);
  ASSERT_EQ(m.delays.size(), 1u);
  EXPECT_TRUE((m.delays[0] - 2 * GiNaC::Pi).is_zero());
  EXPECT_TRUE(m.history[0].is_zero());
}

TEST(EquationModelSource, TheCodeIsTheSameEachTime) {
  // GiNaC orders sums by hash values that change with every new symbol: the printer must not.
  const std::string first = generate_equation_model(scene_equations("equations_impact.toml"), kEngineKeys).code;
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(generate_equation_model(scene_equations("equations_impact.toml"), kEngineKeys).code, first);
  const std::string four = generate_equation_model(scene_equations("equations_two_oscillators.toml"), kEngineKeys).code;
  EXPECT_EQ(generate_equation_model(scene_equations("equations_two_oscillators.toml"), kEngineKeys).code, four);
}

// ---- the expression grammar: the usual conventions, exact numbers ----

TEST(EquationModelSource, ExpressionsFollowTheUsualPrecedenceAndNumbersAreExact) {
  struct Case {
    const char* period;
    GiNaC::ex value;
  };
  for (const Case& c :
       {Case{"2^3*2", 16}, Case{"2*3^2", 18}, Case{"-2^2", -4}, Case{"2-3-4", -5}, Case{"8/4/2", 1},
        Case{"(2+3)*4", 20}, Case{"-(1+2)*3", -9}, Case{"1.5e2", 150}, Case{".5", GiNaC::numeric(1, 2)},
        Case{"1e-3", GiNaC::numeric(1, 1000)}, Case{"0.1+0.2", GiNaC::numeric(3, 10)}, Case{"007", 7},
        Case{"2^(-1)+3", GiNaC::numeric(7, 2)}, Case{"2*pi", 2 * GiNaC::Pi}, Case{"a*b", GiNaC::numeric(-1, 2)}}) {
    toml::table table = scalar_table("x");
    table.insert_or_assign("period", c.period);
    SymbolicEquationModel m = analyse_equations(table, kEngineKeys);
    GiNaC::exmap at{{m.p[0], -1}, {m.p[1], GiNaC::numeric(1, 2)}};
    EXPECT_TRUE((m.period.subs(at) - c.value).is_zero()) << c.period << " read as " << m.period;
  }
  const SymbolicEquationModel m = analyse_equations(scalar_table("-x + 3 - x*x_tau/2"), kEngineKeys);
  EXPECT_TRUE((m.fields[0].f[0] - (3 - m.y[0] - m.y[0] * m.z[0] / 2)).is_zero()) << m.fields[0].f[0];
}

// ---- bad input: every item named ----

struct BadTable {
  const char* what;
  toml::table table;
  std::vector<std::string> expected;  // all in the message
};

template <class Value>
toml::table impact_with(const std::string& entry, Value&& value) {
  toml::table t = impact_table();
  t.insert_or_assign(entry, std::forward<Value>(value));
  return t;
}
toml::table impact_without(const std::string& entry) {
  toml::table t = impact_table();
  t.erase(entry);
  return t;
}
template <class Value>
toml::table impact_parameter(const std::string& name, Value&& value) {
  toml::table t = impact_table();
  t["parameters"].as_table()->insert_or_assign(name, std::forward<Value>(value));
  return t;
}
toml::table impact_state(const std::string& name) {
  toml::table t = impact_with("state", toml::array{"x", name});
  return t;
}
toml::table impact_rhs2(const std::string& expression) { return impact_with("rhs", toml::array{"v", expression}); }

std::vector<BadTable> bad_tables() {
  std::vector<BadTable> cases;
  auto add = [&](const char* what, toml::table table, std::vector<std::string> expected) {
    cases.push_back({what, std::move(table), std::move(expected)});
  };
  // the table itself
  add("unknown entry", impact_with("histroy", toml::table{}), {"`equations.histroy`", "did you mean `history`?"});
  // 11^1e308 was evaluated exactly: GMP aborted or the process took all memory (fuzz mutant 10 598).
  add("huge constant power", impact_with("period", "11^1e308"), {"`equations.period`", "beyond 10000"});
  add("nested constant powers", impact_rhs2("v + 2^(2^(2^(2^2)))"), {"`equations.rhs[2]`", "beyond 10000"});
  add("unknown entry, a prefix", impact_with("param", toml::table{}), {"`equations.param`", "did you mean `parameters`?"});
  add("unknown entry, longer", impact_with("switching", "x"), {"`equations.switching`", "did you mean `switch`?"});
  add("unknown entry, far", impact_with("initial", toml::table{}),
      {"`equations.initial`", "the entries are state, parameters, period, delay, delays, rhs, switch, rhs_switched, history"});
  add("no state", impact_without("state"), {"`equations.state` is required"});
  add("state not an array", impact_with("state", "x"), {"`equations.state`", "array"});
  add("empty state", impact_with("state", toml::array{}), {"`equations.state`", "at least one"});
  add("state not a string", impact_with("state", toml::array{"x", 2}), {"`equations.state[2]`", "a string"});
  // names
  add("name not plain", impact_state("2v"), {"`equations.state[2]`", "`2v`", "plain name"});
  add("leading underscore", impact_state("_v"), {"`equations.state[2]`", "`_v`", "plain name"});
  add("double underscore", impact_state("v__w"), {"`equations.state[2]`", "`v__w`", "reserved"});
  add("keyword", impact_state("int"), {"`equations.state[2]`", "`int`", "C++ keyword"});
  add("alternative token", impact_state("bitor"), {"`equations.state[2]`", "`bitor`", "C++ keyword"});
  add("alternative token and", impact_state("and"), {"`equations.state[2]`", "`and`", "C++ keyword"});
  add("t", impact_state("t"), {"`equations.state[2]`", "`t`", "reserved"});
  add("pi", impact_state("pi"), {"`equations.state[2]`", "`pi`", "reserved"});
  add("GiNaC literal", impact_state("I"), {"`equations.state[2]`", "`I`", "reserved"});
  add("function name", impact_state("exp"), {"`equations.state[2]`", "`exp`", "function"});
  add("_tau suffix", impact_state("x_tau"), {"`equations.state[2]`", "`x_tau`", "_tau"});
  add("duplicate state", impact_state("x"), {"`equations.state[2]`", "`x` is named twice"});
  add("parameter is an engine key", impact_parameter("N", 3),
      {"`equations.parameters.N`", "collides with an engine key"});
  add("parameter is an engine key nev", impact_parameter("nev", 3), {"`equations.parameters.nev`", "engine key"});
  add("parameter is a state", impact_parameter("x", 3), {"`equations.parameters.x`", "also a state"});
  add("parameter keyword", impact_parameter("class", 3), {"`equations.parameters.class`", "C++ keyword"});
  add("parameter text", impact_parameter("g", "1"), {"`equations.parameters.g`", "must be a number"});
  add("parameter bool", impact_parameter("g", true), {"`equations.parameters.g`", "must be a number"});
  add("parameter nan", impact_parameter("g", std::nan("")), {"`equations.parameters.g`", "finite"});
  add("parameters not a table", impact_with("parameters", toml::array{1}), {"`equations.parameters`", "table"});
  // period, delay, history: parameters and pi only
  add("no period", impact_without("period"), {"`equations.period` is required"});
  add("period of t", impact_with("period", "2*pi/omega + t"), {"`equations.period`", "`t` is the time", "position 14"});
  add("delay of a state", impact_with("delay", "x"), {"`equations.delay`", "`x` is a state"});
  add("delay of a delayed state", impact_with("delay", "v_tau"), {"`equations.delay`", "`v_tau` is a delayed state"});
  add("history key", impact_with("history", toml::table{{"V", 1}}),
      {"`equations.history.V`", "not a state", "did you mean `v`?"});
  add("history of t", impact_with("history", toml::table{{"x", "t"}}), {"`equations.history.x`", "`t` is the time"});
  add("history not a table", impact_with("history", toml::array{1, 2}), {"`equations.history`", "table"});
  add("expression not text", impact_with("delay", true), {"`equations.delay`", "expression"});
  // the fields
  add("rhs too long", impact_with("rhs", toml::array{"v", "x", "x"}), {"`equations.rhs`", "has 3 entries", "d = 2"});
  add("rhs too short", impact_with("rhs", toml::array{"v"}), {"`equations.rhs`", "has 1 entries", "d = 2"});
  add("rhs_switched length", impact_with("rhs_switched", toml::array{"v"}),
      {"`equations.rhs_switched`", "has 1 entries"});
  add("no rhs", impact_without("rhs"), {"`equations.rhs` is required"});
  // parse errors: item, expression, position
  add("bad character", impact_rhs2("v $ x"),
      {"`equations.rhs[2]`", "unexpected character `$`", "position 3", "\"v $ x\""});
  add("operator for operand", impact_rhs2("v +* x"), {"`equations.rhs[2]`", "found `*`", "position 4"});
  add("missing operator", impact_rhs2("2x"), {"`equations.rhs[2]`", "missing operator before `x`", "position 2"});
  add("unclosed", impact_rhs2("(v + x"), {"`equations.rhs[2]`", "`(` is not closed", "position 1"});
  add("unmatched", impact_rhs2("v + x)"), {"`equations.rhs[2]`", "`)` without a matching `(`", "position 6"});
  add("ends early", impact_rhs2("v + "), {"`equations.rhs[2]`", "ends after `+`", "position 5"});
  add("empty", impact_rhs2(" "), {"`equations.rhs[2]`", "is empty"});
  add("empty parentheses", impact_rhs2("sin()"), {"`equations.rhs[2]`", "found `)`", "position 5"});
  add("sign after operator", impact_rhs2("x*-v"), {"`equations.rhs[2]`", "sign `-` after an operator", "position 3"});
  add("double sign", impact_rhs2("- -x"), {"`equations.rhs[2]`", "second sign", "position 3"});
  add("power chain", impact_rhs2("x^2^3"), {"`equations.rhs[2]`", "chain of powers", "position 4"});
  add("two arguments", impact_rhs2("sin(x, v)"), {"`equations.rhs[2]`", "`,`", "position 6", "one argument"});
  add("function without argument", impact_rhs2("sin*x"), {"`equations.rhs[2]`", "`sin` without an argument"});
  add("number out of range", impact_rhs2("1e999*x"), {"`equations.rhs[2]`", "out of range"});
  // issue 61 item 3: the symbolic stage bounded before it runs for minutes. A product of 300
  // binomials in x and x_tau (over 60 s of GiNaC before; its first derivatives have some 4.5e5
  // nodes) and 129 delays are refused, naming the entry.
  {
    std::string product = "-x";
    for (int k = 0; k < 300; ++k) product += "*(x + " + std::to_string(k + 1) + "*x_tau)";
    add("derivatives too large", scalar_table(product), {"`equations.rhs[1]`", "its derivatives have more than"});
    toml::table many;
    for (int k = 0; k < 129; ++k) many.insert(std::string("d").append(std::to_string(k)), "1");  // (GCC 12 -Wrestrict)
    toml::table with_many = impact_without("delay");
    with_many.insert_or_assign("delays", many);
    add("too many delays", with_many, {"`equations.delays`", "129 delays, at most 128"});
  }
  add("product out of range", impact_rhs2("1e300*1e300*x"), {"`equations.rhs[2]`", "beyond the range of a double"});
  // names in expressions
  add("unknown name", impact_rhs2("a*omgea^2*sin(omega*t)"),
      {"`equations.rhs[2]`", "unknown name `omgea`", "position 3", "did you mean `omega`?"});
  add("unknown delayed", impact_rhs2("k*(w_tau - v)"),
      {"`equations.rhs[2]`", "unknown name `w_tau`", "did you mean `v_tau`?"});
  add("function not allowed", impact_rhs2("abs(x)"),
      {"`equations.rhs[2]`", "function `abs` is not allowed", "position 1", "sin, cos"});
  add("Heaviside", impact_rhs2("beta*Heaviside(x - e)"),
      {"`equations.rhs[2]`", "function `Heaviside` is not allowed", "position 6"});
  add("parameter called", impact_rhs2("zeta(x)"), {"`equations.rhs[2]`", "`zeta` is not a function"});
  add("GiNaC's constant", impact_rhs2("Pi*x"), {"`equations.rhs[2]`", "unknown name `Pi`", "did you mean `pi`?"});
  // GiNaC's evaluation
  add("complex", impact_rhs2("sqrt(-1)*x"), {"`equations.rhs[2]`", "complex"});
  add("complex power", impact_rhs2("(-8)^(1/3)*x"), {"`equations.rhs[2]`", "complex"});
  add("complex log", impact_rhs2("log(-2)"), {"`equations.rhs[2]`", "complex"});
  add("complex asin", impact_rhs2("x + asin(2)"), {"`equations.rhs[2]`", "complex"});
  add("log of zero", impact_rhs2("log(0)"), {"`equations.rhs[2]`", "cannot be evaluated"});
  add("division by zero", impact_rhs2("x/(e - e)"), {"`equations.rhs[2]`", "cannot be evaluated"});
  // switches
  add("switch without field", impact_without("rhs_switched"),
      {"`equations.rhs_switched` is required with `equations.switch`"});
  add("field without switch", impact_without("switch"),
      {"`equations.rhs_switched` is given without `equations.switch`"});
  add("switch of t and the state", impact_with("switch", "x - e*sin(t)"),
      {"`equations.switch`", "both t and the state"});
  add("switch of a delayed state", impact_with("switch", "x_tau - e"), {"`equations.switch`", "delayed states"});
  add("switch not affine", impact_with("switch", "x^2 - e"), {"`equations.switch`", "affine"});
  add("constant switch", impact_with("switch", "e - 1"), {"`equations.switch`", "neither t nor the state"});
  add("discontinuous",
      impact_with("rhs_switched", toml::array{"v", "a*omega^2*sin(omega*t) + k*(v_tau - v) - 2*zeta*v - x - beta*x"}),
      {"`equations.rhs_switched[2]` differs from `equations.rhs[2]` on switch = 0", "difference", "beta", "e"});
  add("discontinuous first component", impact_with("rhs_switched", toml::array{"v + 1", "a*omega^2*sin(omega*t) - x"}),
      {"`equations.rhs_switched[1]` differs from `equations.rhs[1]`"});
  return cases;
}

TEST(EquationModelSource, EveryBadInputNamesItsItem) {
  for (const BadTable& c : bad_tables()) {
    const std::string message = error_of(c.table);
    ASSERT_FALSE(message.empty()) << c.what << ": accepted";
    for (const auto& part : c.expected) EXPECT_TRUE(contains(message, part)) << c.what << ": " << message;
  }
}

TEST(EquationModelSource, ContinuityIsCheckedOnTheSwitchSurface) {
  // Accepted: the fields agree on H = 0, also when H has a coefficient (2x - 2e = 0), is written
  // in another variable (the contact in v), or the difference vanishes only after expansion.
  EXPECT_EQ(error_of(impact_with("switch", "2*x - 2*e")), "");
  EXPECT_EQ(error_of(impact_with("switch", "e - x")), "");  // the sides swap, continuity holds
  toml::table in_v = impact_table();
  in_v.insert_or_assign("switch", "v/omega - e + 0*x");
  in_v.insert_or_assign(
      "rhs_switched", toml::array{"v", "a*omega^2*sin(omega*t) + k*(v_tau - v) - 2*zeta*v - x - beta*(v - e*omega)^2"});
  EXPECT_EQ(error_of(in_v), "");
  toml::table expanded = impact_table();
  expanded.insert_or_assign(
      "rhs_switched", toml::array{"v", "a*omega^2*sin(omega*t) + k*v_tau - k*v - 2*zeta*v - x - beta*x + beta*e"});
  EXPECT_EQ(error_of(expanded), "");
  // A time window may join discontinuous fields.
  toml::table window = impact_table();
  window.insert_or_assign("switch", "sin(omega*t)");
  window.insert_or_assign("rhs_switched", toml::array{"0", "x"});
  EXPECT_EQ(error_of(window), "");
}

// ---- item 4 of issue 14: nothing of the scene reaches the compiler as text ----

TEST(EquationModelSource, NoFieldSmugglesCodeIntoTheSource) {
  const std::vector<std::string> payloads = {
      "x; system(\"rm -rf ~\")",
      "v */ #include <cstdlib>",
      "a\"); evil(",
      "x\n#include <cstdlib>\nint main() { evil(); }",
      "x // evil",
      "x /* evil */",
      "R\"(evil)\"",
      "__x",
      "int",
      "x_tau",
      "evil()",
      "x\\\nevil",
      "?\?=define evil",  // the trigraph ??= (written ?\? so that the compiler does not warn)
      "x; } struct evil {",
      "std::system",
      "v[0]",
      "p[0]",
      "\xef\xbd\x98",  // a full-width x
  };
  // The words of the payloads that must not appear in the code whatever happens.
  const std::vector<std::string> forbidden = {"system", "rm -rf", "include", "evil", "cstdlib",
                                              "R\"",    "??",     "/*",      "__x",  "main"};
  auto check = [&](const std::string& field, const std::string& payload, const toml::table& table) {
    try {
      const std::string code = generate_equation_model(table, kEngineKeys).code;
      for (const auto& word : forbidden) EXPECT_FALSE(contains(code, word)) << field << " <- " << payload;
    } catch (const BadInput&) {  // refused: exit status 2
    }
  };
  for (const auto& payload : payloads) {
    check("state name", payload, impact_state(payload));
    check("parameter name", payload, impact_parameter(payload, 1.0));
    check("parameter value", payload, impact_parameter("g", payload));
    check("period", payload, impact_with("period", payload));
    check("delay", payload, impact_with("delay", payload));
    check("rhs", payload, impact_rhs2(payload));
    check("switch", payload, impact_with("switch", payload));
    check("rhs_switched", payload, impact_with("rhs_switched", toml::array{"v", payload}));
    check("history key", payload, impact_with("history", toml::table{{payload, 1.0}}));
    check("history value", payload, impact_with("history", toml::table{{"x", payload}}));
    check("table entry", payload, impact_with(payload, "x"));
  }
  // Every payload in an expression is refused, but x_tau, which is the delayed x.
  for (const auto& payload : payloads)
    if (payload != "x_tau") {
      EXPECT_NE(error_of(impact_rhs2(payload)), "") << payload;
    }
  // A harmless but unusual parameter name is accepted and appears nowhere in the code.
  toml::table harmless = impact_parameter("system", 1.0);
  harmless.insert_or_assign("rhs", toml::array{"v", "a*omega^2*sin(omega*t) + k*(v_tau - v) - 2*zeta*v - x*system"});
  harmless.insert_or_assign(
      "rhs_switched", toml::array{"v", "a*omega^2*sin(omega*t) + k*(v_tau - v) - 2*zeta*v - x*system - beta*(x - e)"});
  EXPECT_FALSE(contains(generate_equation_model(harmless, kEngineKeys).code, "system"));
}

TEST(EquationModelSource, NoUserNameAppearsInTheCode) {
  const std::string code = generate_equation_model(scene_equations("equations_impact.toml"), kEngineKeys).code;
  for (const char* name : {"omega", "zeta", "beta", "v_tau", "x_tau"}) EXPECT_FALSE(contains(code, name)) << name;
  const std::string four = generate_equation_model(scene_equations("equations_two_oscillators.toml"), kEngineKeys).code;
  for (const auto& name :
       generate_equation_model(scene_equations("equations_two_oscillators.toml"), kEngineKeys).parameters)
    if (name.size() > 2) {  // one- and two-letter names (F, g, w2) are parts of the code's words
      EXPECT_FALSE(contains(four, name)) << name;
    }
}

// ---- GiNaC's derivatives against finite differences ----

// Central differences of f evaluated by GiNaC at 60 digits: the error of (f(u + h) - f(u - h)) / 2h
// is h^2 |f'''| / 6 + 1e-60 |f| / h, and of the second difference h^2 |f''''| / 12 + 1e-60 |f| / h^2;
// with h = 1e-15 both are below 1e-28 for these smooth fields of order-one values, so a tolerance
// of 1e-20 (relative to 1 + |value|) leaves a wide margin and still fails on any wrong derivative.
void expect_derivatives_match_differences(const SymbolicEquationModel& m, const GiNaC::exmap& at) {
  const long saved_digits = GiNaC::Digits;
  GiNaC::Digits = 60;
  const GiNaC::numeric h("1e-15");
  auto value = [&](const GiNaC::ex& e, const GiNaC::exmap& point) { return GiNaC::evalf(e.subs(point)); };
  auto shifted = [&](const GiNaC::symbol& s, const GiNaC::numeric& by) {
    GiNaC::exmap point = at;
    point[s] = at.at(s) + by;
    return point;
  };
  auto expect_close = [&](const GiNaC::ex& symbolic, const GiNaC::ex& difference, const std::string& what) {
    const GiNaC::ex s = value(symbolic, at);
    const double error = to_double(GiNaC::abs(s - GiNaC::evalf(difference)) / (1 + GiNaC::abs(s)));
    EXPECT_LT(error, 1e-20) << what << ": " << s << " vs " << GiNaC::evalf(difference);
  };
  for (size_t j = 0; j < m.fields.size(); ++j) {
    const auto& field = m.fields[j];
    for (int i = 0; i < m.d(); ++i) {
      const GiNaC::ex& f = field.f[i];
      const std::string where = "field " + std::to_string(j) + " component " + std::to_string(i);
      for (int a = 0; a < m.d(); ++a) {
        expect_close(field.A[i][a], (value(f, shifted(m.y[a], h)) - value(f, shifted(m.y[a], -h))) / (2 * h),
                     where + " A column " + std::to_string(a));
        expect_close(field.B[i][a], (value(f, shifted(m.z[a], h)) - value(f, shifted(m.z[a], -h))) / (2 * h),
                     where + " B column " + std::to_string(a));
      }
      expect_close(field.f_t[i], (value(f, shifted(m.t, h)) - value(f, shifted(m.t, -h))) / (2 * h), where + " f_t");
      expect_close(field.f_tt[i], (value(f, shifted(m.t, h)) - 2 * value(f, at) + value(f, shifted(m.t, -h))) / (h * h),
                   where + " f_tt");
    }
  }
  for (size_t a = 0; a < m.grad_H.size(); ++a)
    expect_close(
        m.grad_H[a],
        (value(m.switch_function, shifted(m.y[a], h)) - value(m.switch_function, shifted(m.y[a], -h))) / (2 * h),
        "grad H " + std::to_string(a));
  GiNaC::Digits = saved_digits;
}

// A point: state, delayed state, t and the parameters at exact rationals (parameters at their
// table values would do as well; rationals keep the evaluation exact up to Digits).
GiNaC::exmap point_of(const SymbolicEquationModel& m, int seed) {
  GiNaC::exmap at;
  at[m.t] = GiNaC::numeric(7 + seed, 5);
  for (int i = 0; i < m.d(); ++i) {
    at[m.y[i]] = GiNaC::numeric(3 * i + 1 + seed, 10 + i);
    at[m.z[i]] = GiNaC::numeric(-2 * i - 1 - seed, 7 + i);
  }
  for (size_t k = 0; k < m.p.size(); ++k) at[m.p[k]] = GiNaC::numeric(static_cast<long>(k) + 2, 3);
  return at;
}

TEST(EquationModelSource, DerivativesOfTheImpactModelMatchFiniteDifferences) {
  const SymbolicEquationModel m = analyse_equations(impact_table(), kEngineKeys);
  ASSERT_EQ(m.fields.size(), 2u);
  for (int seed : {0, 1}) expect_derivatives_match_differences(m, point_of(m, seed));
  // and the impact model's Jacobian jump is -beta in dv'/dx: A_1 - A_2 = -beta e_2 e_1^T
  const GiNaC::symbol& beta = m.p[1];
  EXPECT_TRUE((m.fields[0].A[1][0] - m.fields[1].A[1][0] + beta).is_zero());
}

TEST(EquationModelSource, DerivativesOfEveryFunctionMatchFiniteDifferences) {
  toml::table table{
      {"state", toml::array{"x", "y", "w"}},
      {"parameters", toml::table{{"a", 0.3}, {"b", 7}, {"c", -1.5}, {"q", 4}}},
      {"period", "2*pi/q"},
      {"rhs", toml::array{"sin(a*x)*cos(y_tau) - tan(w/7) + asin(x/10) + 1e-3*x - .5e+1*w_tau",
                          "acos(y/10)*atan(w) + sinh(x/3)*cosh(w_tau/4) - tanh(y) + (x - y)*(w - x)*c - (y - x)^3",
                          "exp(-x/5)*log(2 + y^2) + sqrt(1 + w^2) - x^3/(1 + y^2) - q/(b - x)^2 + (x*w + 4)^(1/3) "
                          "+ t*sin(q*t)^2 - 1/sqrt(2 + x_tau^2)"}},
      {"switch", "sin(q*t) - 1/2"},
      {"rhs_switched", toml::array{"x_tau*exp(t/3)", "y^2*w_tau", "cos(t)*sin(x + y + w)"}}};
  const SymbolicEquationModel m = analyse_equations(table, kEngineKeys);
  ASSERT_EQ(m.fields.size(), 2u);
  for (int seed : {0, 1, 2}) expect_derivatives_match_differences(m, point_of(m, seed));
}

TEST(EquationModelSource, TheTwoOscillatorDerivativesMatchFiniteDifferences) {
  const SymbolicEquationModel m = analyse_equations(scene_equations("equations_two_oscillators.toml"), kEngineKeys);
  for (int seed : {0, 1}) expect_derivatives_match_differences(m, point_of(m, seed));
}

TEST(EquationModelSource, TermsThatAreNotFiniteAtAPointAreNamed) {
  const toml::table table{
      {"state", toml::array{"x", "v"}},
      {"parameters", toml::table{{"a", 2.0}}},
      {"period", "1"},
      {"rhs", toml::array{"v", "a*x^(1/3) + log(v_tau)"}},
      {"history", toml::table{{"x", "1"}, {"v", "1"}}},
  };
  const SymbolicEquationModel m = analyse_equations(table, kEngineKeys);
  // x = 1, v_tau = 1: every term (and derivative) finite.
  EXPECT_TRUE(terms_not_finite(m, 0, {1, 0}, {0, 1}, {2.0}).empty());
  // x = 0: d/dx (a x^(1/3)) = a/3 x^(-2/3) is 1/0; nothing else is.
  const std::vector<std::string> at_zero = terms_not_finite(m, 0.5, {0, 0}, {0, 1}, {2.0});
  ASSERT_EQ(at_zero.size(), 1u);
  EXPECT_EQ(at_zero[0].rfind("`equations.rhs[2] = \"a*x^(1/3) + log(v_tau)\"`: its derivative by x, ", 0), 0u)
      << at_zero[0];
  EXPECT_TRUE(contains(at_zero[0], "is undefined")) << at_zero[0];
  // v_tau = 0: log(0) is a pole (the derivative 1/v_tau is not looked at once f is not finite).
  const std::vector<std::string> log_zero = terms_not_finite(m, 0, {1, 0}, {0, 0}, {2.0});
  ASSERT_EQ(log_zero.size(), 1u);
  EXPECT_TRUE(contains(log_zero[0], "`equations.rhs[2] = ") && contains(log_zero[0], "\"` is undefined")) << log_zero[0];
  // x = -1: (-1)^(1/3) is complex, as std::pow(-1, 1/3.) is NaN.
  const std::vector<std::string> negative = terms_not_finite(m, 0, {-1, 0}, {0, 1}, {2.0});
  ASSERT_EQ(negative.size(), 1u);
  EXPECT_TRUE(contains(negative[0], "` is not a real number")) << negative[0];
  // The first component (v) is never reported.
  for (const auto& lines : {at_zero, log_zero, negative})
    for (const auto& line : lines) EXPECT_FALSE(contains(line, "rhs[1]")) << line;
}

}  // namespace
