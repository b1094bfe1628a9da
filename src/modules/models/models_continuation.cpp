// The continuation of the analyses of the built-in models in this module
// (model_analyses_continuation.hpp), apart from their other analyses (analyses_<model>.cpp),
// as the impact model's in the library (src/engine/analyses_continuation.cpp).
#include "delayspec/builtin_analyses.hpp"
#include "delayspec/model_analyses_continuation.hpp"

namespace delayspec {

DELAYSPEC_INSTANTIATE_CONTINUATION(LinearModel)
DELAYSPEC_INSTANTIATE_CONTINUATION(MathieuModel)
DELAYSPEC_INSTANTIATE_CONTINUATION(MackeyGlassModel)
DELAYSPEC_INSTANTIATE_CONTINUATION(MillingModel)
DELAYSPEC_INSTANTIATE_CONTINUATION(VariablePitchMillingModel)

}  // namespace delayspec
