#include "scene/problem/problem.hpp"

#include <climits>

#include "delayspec/errors.hpp"
#include "delayspec/grid.hpp"
#include "scene/equations/equation_model.hpp"
#include "scene/output/metadata.hpp"
#include "scene/problem/builtin_family.hpp"
#include "scene/problem/models_module_loader.hpp"

namespace delayspec::cli {

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
      {"impact", read_impact_family, true, {"x", "v"}},
      {"linear", read_linear_family, false, {"x"}},
      {"mathieu", read_mathieu_family, true, {"x", "v"}},
      {"mackey-glass", read_mackey_glass_family, false, {"x"}},
      {"milling", read_milling_family, true, {"x", "v"}},
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

size_t read_plot_component(Config& config, const Problem& problem) {
  return state_component("plot_component", config.get_string("plot_component", "1"), problem.state_names);
}

Problem read_problem(Config& config, int default_N, ModelNeed need) {
  Problem problem;
  problem.model_name = config.get_choice("model", model_names().front(), model_choices());
  const BuiltinModel* builtin = nullptr;
  for (const auto& model : builtin_models())
    if (model.name == problem.model_name) builtin = &model;
  if (builtin) {
    const std::shared_ptr<const BuiltinFamily> family = builtin->read(config);
    problem.model = family->model_at(family->base_values());
    problem.family = family;
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
    problem.family = std::move(equations.family);
    problem.state_names = std::move(equations.state);
    // named by the scene file that holds the [equations] table (read above; a Python dict has no
    // file name)
    const std::string& origin = config.origin("equations");
    problem.model_label = model_label(problem.model_name, problem.state_names,
                                      origin.ends_with(".toml") ? std::optional(origin) : std::nullopt);
  }
  if (builtin) problem.model_label = problem.model_name;
  // N up to 1e9 (the history alone is then 16 GB at d = 2); orbit_period and contact_substeps
  // multiply the work per step or per period, 1000 is far beyond any use.
  problem.N = static_cast<int>(config.get_int_in_range("N", default_N, 1, 1'000'000'000));
  problem.orbit_period = static_cast<int>(config.get_int_in_range("orbit_period", 1, 1, 1000));
  if (problem.orbit_period != 1 && !problem.forced)
    throw BadInput("`orbit_period = " + std::to_string(problem.orbit_period) +
                   "`: only for forced models (impact, mathieu, milling); for linear and mackey-glass set `period`");
  problem.events = parse_event_mode(config.get_choice("events", "on", event_mode_names()));
  problem.jacobian = config.get_enum("jacobian", JacobianMode::consistent,
                                     {{"consistent", JacobianMode::consistent}, {"frozen", JacobianMode::frozen}});
  problem.contact_substeps =
      static_cast<int>(config.get_int_in_range("contact_substeps", problem.contact_substeps, 1, 1000));
  problem.grid_layout =
      config.get_enum("grid", GridLayout::aligned, {{"aligned", GridLayout::aligned}, {"uniform", GridLayout::uniform}});
  // BadInput now when N does not fit the delay/period ratio, or when two histories (the state and
  // the vector a step map is applied to: the least any analysis holds) exceed the memory
  // (memory_budget.hpp; each analysis bounds its own larger arrays before allocating them).
  problem.parameter_values = problem.family->base_values();
  const FamilyMember member = problem.family->at(problem.parameter_values, problem.map_settings());
  if (!member) throw BadInput(member.rejected);
  problem.analyses = member.analyses;
  return problem;
}

std::optional<Problem> problem_at(const Problem& base, const std::vector<double>& values, int N,
                                  std::string& rejected) {
  Problem problem = base;
  problem.N = N;
  problem.parameter_values = values;
  const FamilyMember member = problem.family->at(values, problem.map_settings());
  if (!member) {
    rejected = member.rejected;
    return std::nullopt;
  }
  problem.analyses = member.analyses;
  // The built-in model itself (bench's classic discretisations) at these values too.
  if (problem.model) problem.model = dynamic_cast<const BuiltinFamily&>(*problem.family).model_at(values);
  return problem;
}

int family_parameter(const Problem& problem, const std::string& item, const std::string& key) {
  const int index = problem.family->index_of(key);
  if (index >= 0) return index;
  std::string names;
  for (const std::string& name : problem.family->parameter_names()) names += (names.empty() ? "" : ", ") + name;
  throw BadInput("`" + item + " = " + key + "`: not a model parameter of model " + problem.model_name +
                 " (its parameters: " + names + ")");
}

Problem starting_problem(const Problem& problem, Config& config, const std::vector<ParameterSetting>& settings) {
  std::vector<double> values = problem.parameter_values;
  std::string keys;
  for (const ParameterSetting& s : settings) {
    values = ProblemFamily::with(values, family_parameter(problem, s.item, s.key), s.value);
    keys += (keys.empty() ? "`" : ", `") + s.origin + " = " + format_number(s.value) + "`";
  }
  std::string rejected;
  std::optional<Problem> at = problem_at(problem, values, problem.N, rejected);
  if (!at) throw BadInput(keys + ": " + rejected);
  // Given, as far as the output's metadata says: the run starts there.
  for (const ParameterSetting& s : settings) {
    config.set(s.key, format_number(s.value), s.origin);
    config.mark_used(s.key);
  }
  return *at;
}

AnalysesAt analyses_along(const Problem& problem, int index) {
  return delayspec::analyses_along(problem.family, problem.parameter_values, index, problem.map_settings());
}

}  // namespace delayspec::cli
