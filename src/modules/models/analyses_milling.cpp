// The analyses of the built-in model MillingModel, compiled once here in libdelayspec_models
// (src/modules/models/models_module.hpp).
#include "delayspec/builtin_analyses.hpp"

namespace delayspec {
template class ModelAnalysesFor<MillingModel>;
}  // namespace delayspec
