// The analyses of the built-in model LinearModel, compiled once here in libdelayspec_models
// (src/modules/models/models_module.hpp).
#include "delayspec/builtin_analyses.hpp"

namespace delayspec {
template class ModelAnalysesFor<LinearModel>;
}  // namespace delayspec
