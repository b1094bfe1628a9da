// The continuation of the impact model's analyses (model_analyses_continuation.hpp), compiled
// once here, apart from its other analyses (analyses_impact.cpp). The other built-in models' are
// in libdelayspec_models (src/modules/models/models_continuation.cpp).
#include "delayspec/builtin_analyses.hpp"
#include "delayspec/model_analyses_continuation.hpp"

namespace delayspec {

DELAYSPEC_INSTANTIATE_CONTINUATION(ImpactModel)

}  // namespace delayspec
