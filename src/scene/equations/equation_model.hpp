#pragma once
// model = equations: a model written in the scene's [equations] table (docs/models.md). The
// table is checked, differentiated and printed as C++ by GiNaC (src/modules/equations, a module loaded
// on first use: equations_module_loader.hpp), then compiled at run time and loaded
// (equation_plugin.hpp); a table compiled before is found by its text, without GiNaC (the
// record kept beside the object). Its parameters are keys like those of
// any model (`--set k=0.3`, sweep_key, chart_x), read here with the table's values as defaults,
// so a new parameter value never recompiles. The delay is the `delay` expression, or
// tau_over_T times the period when that key is given.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "scene/keys/config.hpp"
#include "delayspec/problem_family.hpp"

namespace delayspec::cli {

struct EquationModel {
  std::vector<std::string> state;       // the state's names (output columns)
  std::vector<std::string> parameters;  // the parameters' names (keys)
  // The compiled model at any parameter values (problem_family.hpp): the parameters, and
  // tau_over_T for a model of one delay; its base values are the scene's.
  std::shared_ptr<const ProblemFamily> family;
};

// Reads the [equations] table (kept whole by Config as the key `equations`), the parameter keys,
// tau_over_T and model_cache. BadInput for every input error, naming the item. `check_grid(taus,
// names, period)` is called with the delays (and their items, for messages) and period before the model is compiled, so that a grid that
// cannot be made (a delay shorter than a step, too many steps) is refused in milliseconds.
// `check_autonomy(autonomous)` likewise, when the model is compiled in this run (a cached one
// costs nothing to load; its analyses say it then).
EquationModel read_equation_model(Config& config,
                                  const std::function<void(const std::vector<double>& taus, const std::vector<std::string>& names,
                                                           double period)>& check_grid,
                                  const std::function<void(bool autonomous)>& check_autonomy = {});

// The keys an equation parameter may not be named after: those the engine reads whatever the
// model (N, nev, seed, ...: keys_of_every_model), and model, equations, tau_over_T and model_cache.
std::vector<std::string> engine_keys(const KeyIndex& index);

}  // namespace delayspec::cli
