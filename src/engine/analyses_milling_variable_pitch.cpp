// The analyses of the built-in model VariablePitchMillingModel, compiled once here
// (builtin_analyses.hpp).
#include "delayspec/builtin_analyses.hpp"

namespace delayspec {
template class ModelAnalysesFor<VariablePitchMillingModel>;
}  // namespace delayspec
