#include "scene/problem/problem.hpp"

#include <climits>

#include "delayspec/errors.hpp"
#include "delayspec/memory_budget.hpp"
#include "delayspec/grid.hpp"
#include "scene/equations/equation_model.hpp"
#include "scene/problem/models_module_loader.hpp"

namespace delayspec::cli {

namespace {

ImpactModel read_impact(Config& c) {
  ImpactParameters p;
  p.zeta = c.get_double("zeta", p.zeta);
  p.e = c.get_double("e", p.e);
  p.a = c.get_double("a", p.a);
  p.beta = c.get_double("beta", p.beta);
  p.omega = c.get_double("omega", p.omega);
  p.k = c.get_double("k", p.k);
  p.x0 = c.get_double("x0", p.x0);
  p.v0 = c.get_double("v0", p.v0);
  if (c.has("tau") && c.has("tau_over_T")) throw BadInput("`tau` and `tau_over_T` are both given: give one of them");
  if (c.has("tau")) {
    p.tau = c.get_double("tau", 0);
    require_positive("tau", p.tau);
  } else {
    p.tau_over_T = c.get_double("tau_over_T", p.tau_over_T);
    require_positive("tau_over_T", p.tau_over_T);
  }
  return ImpactModel(p);
}

LinearModel read_linear(Config& c) {
  LinearParameters p;
  p.a = c.get_double("a", p.a);
  p.b = c.get_double("b", p.b);
  p.tau = c.get_double("tau", p.tau);
  p.period = c.get_double("period", p.tau);
  return LinearModel(p);
}

MathieuModel read_mathieu(Config& c) {
  MathieuParameters p;
  p.kappa = c.get_double("kappa", p.kappa);
  p.delta = c.get_double("delta", p.delta);
  p.eps = c.get_double("eps", p.eps);
  p.b = c.get_double("b", p.b);
  return MathieuModel(p);
}

MackeyGlassModel read_mackey_glass(Config& c) {
  MackeyGlassParameters p;
  p.beta = c.get_double("beta", p.beta);
  p.gamma = c.get_double("gamma", p.gamma);
  p.n = c.get_double("n", p.n);
  p.tau = c.get_double("tau", p.tau);
  p.period = c.get_double("period", p.tau);
  p.x0 = c.get_double("x0", p.x0);
  return MackeyGlassModel(p);
}

// Equal pitch unless `pitch_angles` gives unequal spacings (VariablePitchMillingModel); angles all
// equal are the equal-pitch tool, the same model as without them.
AnyModel read_milling(Config& c) {
  MillingParameters p;
  p.spindle_rpm = c.get_double("spindle_rpm", p.spindle_rpm);
  p.depth = c.get_double("depth", p.depth);
  p.radial_immersion = c.get_double("radial_immersion", p.radial_immersion);
  // The model names the allowed range (1..kMaxTeeth) in its own message; the wide range here
  // only keeps the cast safe.
  p.teeth = static_cast<int>(c.get_int_in_range("teeth", p.teeth, 1, MillingModel::kMaxTeeth));
  // `equal` (what --help prints as the default) is accepted as a value too: the equal pitch.
  if (c.get_string("pitch_angles", "equal") != "equal") p.pitch_angles = c.get_double_list("pitch_angles", "equal");
  p.Kt = c.get_double("Kt", p.Kt);
  p.Kn = c.get_double("Kn", p.Kn);
  p.omega_n = c.get_double("omega_n", p.omega_n);
  p.zeta = c.get_double("zeta", p.zeta);
  p.mass = c.get_double("mass", p.mass);
  p.direction = c.get_choice("milling", "down", {"down", "up"}) == "up" ? MillingDirection::up : MillingDirection::down;
  p.x0 = c.get_double("x0", p.x0);
  p.v0 = c.get_double("v0", p.v0);
  if (p.pitch_angles.empty()) return MillingModel(p);
  if (!c.has("teeth")) p.teeth = static_cast<int>(std::min<size_t>(p.pitch_angles.size(), MillingModel::kMaxTeeth + 1));
  const VariablePitchMillingModel variable(p);  // (checks the angles against the teeth)
  if (variable.distinct_pitches() > 1) return variable;
  p.pitch_angles.clear();
  return MillingModel(p);
}

}  // namespace

StepOptions step_options(const Problem& problem) {
  StepOptions options;
  options.events = problem.events;
  options.jacobian = problem.jacobian;
  options.contact_substeps = problem.contact_substeps;
  options.grid = problem.grid_layout;
  return options;
}

HistoryGrid Problem::grid() const { return analyses->grid(map_settings()); }

int Problem::state_dimension() const { return analyses->state_dimension(); }

MapSettings Problem::map_settings() const { return {N, orbit_period, step_options(*this)}; }

std::string to_string(EventMode mode) {
  switch (mode) {
    case EventMode::on: return "on";
    case EventMode::linear: return "linear";
    case EventMode::off: return "off";
  }
  return "?";
}

std::string to_string(JacobianMode mode) { return mode == JacobianMode::frozen ? "frozen" : "consistent"; }

std::string to_string(GridLayout layout) { return layout == GridLayout::uniform ? "uniform" : "aligned"; }

const std::vector<std::string>& event_mode_names() {
  static const std::vector<std::string> names = {"on", "linear", "off"};
  return names;
}

EventMode parse_event_mode(const std::string& text, const std::string& key) {
  for (EventMode mode : {EventMode::on, EventMode::linear, EventMode::off})
    if (to_string(mode) == text) return mode;
  throw BadInput("`" + key + " = " + text + "`: must be one of on, linear, off");
}

const std::vector<BuiltinModel>& builtin_models() {
  // The default first. Forced: a periodic forcing sets the map's period (orbit_period counts its
  // periods); linear and mackey-glass are autonomous, their map's period is the key `period`.
  static const std::vector<BuiltinModel> table = {
      {"impact", [](Config& c) -> AnyModel { return read_impact(c); }, true, {"x", "v"}},
      {"linear", [](Config& c) -> AnyModel { return read_linear(c); }, false, {"x"}},
      {"mathieu", [](Config& c) -> AnyModel { return read_mathieu(c); }, true, {"x", "v"}},
      {"mackey-glass", [](Config& c) -> AnyModel { return read_mackey_glass(c); }, false, {"x"}},
      {"milling", read_milling, true, {"x", "v"}},
  };
  return table;
}

const std::vector<std::string>& model_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all;
    for (const auto& model : builtin_models()) all.push_back(model.name);
    return all;
  }();
  return names;
}

const std::vector<std::string>& model_choices() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all = model_names();
    all.push_back("equations");
    return all;
  }();
  return names;
}

std::string autonomous_fixed_point_note(const Problem& problem) {
  if (!problem.analyses->is_autonomous()) return "";
  return "model `" + problem.model_name +
         "` is autonomous: this follows the fixed point of the stroboscopic map over the sampling period (what the "
         "history reaches, often an equilibrium); for equilibria and their Hopf points use `continue` with "
         "`continue_object = equilibrium`, for the orbits born there add `continue_switch = true`, for one orbit "
         "`floquet` with `period_guess`";
}

void require_autonomous_model(bool autonomous, const std::string& model_name, bool builtin) {
  if (!autonomous)
    throw BadInput("`model = " + model_name + "` is not autonomous: " +
                   (builtin ? "its forcing depends on t" : "its right-hand side depends on t, or it switches") +
                   "; equilibria are for models with no forcing (linear, mackey-glass, or equations without t)");
}

Problem read_problem(Config& config, int default_N, ModelNeed need) {
  Problem problem;
  problem.model_name = config.get_choice("model", model_names().front(), model_choices());
  const BuiltinModel* builtin = nullptr;
  for (const auto& model : builtin_models())
    if (model.name == problem.model_name) builtin = &model;
  if (builtin) {
    problem.model = builtin->read(config);
    problem.analyses = builtin_model_analyses(*problem.model);
    problem.state_names = builtin->state_names;
    problem.forced = builtin->forced;
  } else {
    EquationModel equations = read_equation_model(
        config,
        [&](const std::vector<double>& taus, const std::vector<std::string>& names, double period) {
          make_grid(taus, period, static_cast<int>(config.get_int_in_range("N", default_N, 1, 1'000'000'000)),
                    static_cast<int>(config.get_int_in_range("orbit_period", 1, 1, 1000)), names);
        },
        [&](bool autonomous) {
          if (need == ModelNeed::autonomous) require_autonomous_model(autonomous, "equations", false);
        });
    problem.analyses = std::move(equations.analyses);
    problem.state_names = std::move(equations.state);
  }
  // N up to 1e9 (the history alone is then 16 GB at d = 2); orbit_period and contact_substeps
  // multiply the work per step or per period, 1000 is far beyond any use.
  problem.N = static_cast<int>(config.get_int_in_range("N", default_N, 1, 1'000'000'000));
  problem.orbit_period = static_cast<int>(config.get_int_in_range("orbit_period", 1, 1, 1000));
  if (problem.orbit_period != 1 && !problem.forced)
    throw BadInput("`orbit_period = " + std::to_string(problem.orbit_period) +
                   "`: only for forced models (impact, mathieu, milling); for linear and mackey-glass set `period`");
  problem.events = parse_event_mode(config.get_choice("events", "on", event_mode_names()));
  problem.jacobian = config.get_choice("jacobian", "consistent", {"consistent", "frozen"}) == "frozen"
                         ? JacobianMode::frozen
                         : JacobianMode::consistent;
  problem.contact_substeps =
      static_cast<int>(config.get_int_in_range("contact_substeps", problem.contact_substeps, 1, 1000));
  const bool uniform = config.get_choice("grid", "aligned", {"aligned", "uniform"}) == "uniform";
  problem.grid_layout = uniform ? GridLayout::uniform : GridLayout::aligned;
  // BadInput now when N does not fit the delay/period ratio, or when two histories (the state and
  // the vector a step map is applied to: the least any analysis holds) exceed the memory
  // (memory_budget.hpp; each analysis bounds its own larger arrays before allocating them).
  const long n = problem.grid().dimension(problem.state_dimension());
  require_memory(2 * 8.0 * static_cast<double>(n), "`N = " + std::to_string(problem.N) + "`",
                 "two histories of d (N + 1) = " + std::to_string(n) + " doubles");
  return problem;
}

}  // namespace delayspec::cli
