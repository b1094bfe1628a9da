// The analyses of the built-in model ImpactModel, compiled once here (builtin_analyses.hpp).
#include "delayspec/builtin_analyses.hpp"

namespace delayspec {
template class ModelAnalysesFor<ImpactModel>;
}  // namespace delayspec
