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

namespace delayspec::cli {

struct Problem {
  std::string model_name;
  std::optional<AnyModel> model;                  // the built-in model; empty for model = equations
  std::shared_ptr<const ModelAnalyses> analyses;  // every model
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
  AnyModel (*read)(Config& config);
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

// For the commands that follow the fixed point of the stroboscopic map (continue, chart,
// boundary): on an autonomous model, which has no forcing period, what that fixed point is and
// where the orbits and equilibria are followed instead; empty for a forced model (issue 61 item 7).
std::string autonomous_fixed_point_note(const Problem& problem);

// BadInput unless the model is autonomous (equilibria need a model with no forcing). builtin:
// the model is one of the built-in ones (its forcing, else the equations' t or switch, named).
void require_autonomous_model(bool autonomous, const std::string& model_name, bool builtin);

}  // namespace delayspec::cli
