#pragma once
// The analyses of a built-in model: the impact model's from the library, the other models' from
// libdelayspec_models (src/modules/models/models_module.hpp), loaded on first use
// (scene/loading/module_loader.hpp), so that the program builds and runs its default scene
// without that module.
#include <memory>
#include <string>

#include "delayspec/model_analyses.hpp"
#include "modules/models/models_module.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

// The model wrapped in its analyses. BadInput (exit 2) naming the module's file when the model
// needs the module and it is missing, cannot be loaded or is of another build (load_module).
std::shared_ptr<const ModelAnalyses> builtin_model_analyses(const AnyModel& model);

// The classic dense discretisations (sdm0, fdm1) of the problem's model (the module's
// classic_multipliers_of), for `bench`. BadInput for model = equations, for a model they do not
// take, and as builtin_model_analyses when the module cannot be loaded.
ClassicResult builtin_classic_multipliers(const Problem& problem, int m, ClassicMethod method, int nev);

// The module beside libdelayspec, loaded on the first call (thread-safe); `model_name` is the
// model that needs it, for the message of a failed load.
const ModelsModule& models_module(const std::string& model_name);

}  // namespace delayspec::cli
