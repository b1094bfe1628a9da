// The analyses of the built-in model MillingModel, compiled once here (builtin_analyses.hpp).
#include "delayspec/builtin_analyses.hpp"

namespace delayspec {
template class ModelAnalysesFor<MillingModel>;
}  // namespace delayspec
