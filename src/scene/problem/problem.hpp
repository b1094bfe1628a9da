#pragma once
// Problem: what every command needs to know about the system being studied: the model, the
// resolution N and the discretisation options; the grid and the dimensions follow from them.
// Read from a Config; every key it reads is documented in the CLI contract.
//
// The model's analyses (delayspec/model_analyses.hpp) are the one hand-off from a problem to the
// engine, for the built-in models and for a model written as equations in the scene alike.
// What only the built-in models offer (the classic discretisations of `bench`) takes the
// AnyModel itself (models_module_loader.hpp).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scene/keys/config.hpp"
#include "modules/models/any_model.hpp"
#include "delayspec/grid.hpp"
#include "delayspec/model_analyses.hpp"
#include "delayspec/problem_family.hpp"

namespace delayspec::cli {

class BuiltinFamily;

struct Problem {
  std::string model_name;   // the key `model`: a built-in model's name, or "equations"
  std::string model_label;  // how outputs name it (metadata.hpp's model_label: the scene file's stem)
  std::optional<AnyModel> model;                  // the built-in model; empty for model = equations
  std::shared_ptr<const ModelAnalyses> analyses;  // every model
  // The model at other parameter values (problem_family.hpp), and this problem's values: what
  // continue and boundary vary, set as doubles, never by the scene's keys again.
  std::shared_ptr<const ProblemFamily> family;
  std::vector<double> parameter_values;
  std::vector<std::string> state_names;           // the state's components: "x", "v" (output columns)
  // Whether a periodic forcing sets the map's period (orbit_period counts forcing periods); an
  // equation model's period is its own, so it may take several.
  bool forced = true;
  int N = 100;
  int orbit_period = 1;
  EventMode events = EventMode::on;
  JacobianMode jacobian = JacobianMode::consistent;
  int contact_substeps = StepOptions{}.contact_substeps;  // trapezoid sub-steps per contact piece
  GridLayout grid_layout = GridLayout::aligned;           // the key `grid` (step_options.hpp)

  // The grid of this problem: a function of (model, N, orbit_period), never a stored copy.
  HistoryGrid grid() const;
  // d: the model's state dimension.
  int state_dimension() const;
  // n = d (M + 1): the dimension of the map's history vector (and of the monodromy).
  long dimension() const { return grid().dimension(state_dimension()); }
  // N, orbit_period and the step options, as the analyses take them.
  MapSettings map_settings() const;
  // Whether the model switches, in its state (impact) or in time (milling).
  bool switching() const { return analyses->switches_in_state() || analyses->switches_in_time(); }
};

// The stepper options (events, jacobian, contact sub-steps) the problem asks for.
StepOptions step_options(const Problem& problem);

// The one table of the built-in models, the default first: the name (the key `model`), how the
// keys make the model, and the traits the scene layer needs beside its analyses.
struct BuiltinModel {
  std::string name;
  std::shared_ptr<const BuiltinFamily> (*read)(Config& config);  // builtin_family.hpp
  bool forced;                           // Problem::forced
  std::vector<std::string> state_names;  // Problem::state_names
};
const std::vector<BuiltinModel>& builtin_models();
// Their names, the default first.
const std::vector<std::string>& model_names();
// The values of the key `model`: the built-in models and "equations" (a model written in the
// scene's [equations] table, equation_model.hpp).
const std::vector<std::string>& model_choices();

// The key values of `events`, `jacobian` and `grid` (the JSON and text edge): "on", "linear",
// "off"; "consistent", "frozen"; "aligned", "uniform". parse_* throw BadInput naming `key` for any
// other text.
std::string to_string(EventMode mode);
std::string to_string(JacobianMode mode);
std::string to_string(GridLayout layout);
EventMode parse_event_mode(const std::string& text, const std::string& key = "events");
const std::vector<std::string>& event_mode_names();

// What a command needs of the model, checked as early as it can be: an equations model that
// equilibrium cannot take is refused before its compile (seconds), not after.
enum class ModelNeed { any, autonomous };

// Reads `model` and its parameters, N, orbit_period, events, jacobian, contact_substeps, grid.
// default_N is used when the key N is absent.
Problem read_problem(Config& config, int default_N = 100, ModelNeed need = ModelNeed::any);

// The same problem at other parameter values (its family's, in their order) and resolution N:
// nothing, with the model's reason in `rejected`, when the model refuses them or the grid of N
// cannot be made at them. The discretisation options are base's.
std::optional<Problem> problem_at(const Problem& base, const std::vector<double>& values, int N,
                                  std::string& rejected);

// The index of model parameter `key` in the problem's family; BadInput naming `item = key` and
// the model's parameters when it has none of that name (N, model, a command's own key, ...).
int family_parameter(const Problem& problem, const std::string& item, const std::string& key);

// The problem where a continuation or a boundary starts: `problem` (the scene's, read_problem)
// with each setting's key, a model parameter (family_parameter names `item` when it is not), set
// to its value through the family. The values are recorded in `config` as given from `origin`
// (the output's metadata). BadInput naming the origins when the model refuses the values. Called
// after the command has read its other keys (with the scene's problem, whose values they do not
// depend on), so that --help lists them all whatever the placeholder keys.
struct ParameterSetting {
  std::string item, key;  // "continue_key", "b"
  double value;
  std::string origin;  // "continue_from"
};
Problem starting_problem(const Problem& problem, Config& config, const std::vector<ParameterSetting>& settings);

// The problem along its parameter `index`, at its own N and other values (continuation's family
// of models, problem_family.hpp's analyses_along).
AnalysesAt analyses_along(const Problem& problem, int index);

// For the commands that follow the fixed point of the stroboscopic map (continue, chart,
// boundary): on an autonomous model, which has no forcing period, what that fixed point is and
// where the orbits and equilibria are followed instead; empty for a forced model (issue 61 item 7).
std::string autonomous_fixed_point_note(const Problem& problem);

// The key plot_component: the state component (0-based) that a branch's figures and tables show,
// a state name or a 1-based index, default the first (issue 61 item 8). continue reads it (its
// table; the files record it for plot) and plot (which may override it).
size_t read_plot_component(Config& config, const Problem& problem);

// BadInput unless the model is autonomous (equilibria need a model with no forcing). builtin:
// the model is one of the built-in ones (its forcing, else the equations' t or switch, named).
void require_autonomous_model(bool autonomous, const std::string& model_name, bool builtin);

}  // namespace delayspec::cli
