// The continuation of the built-in models' analyses (model_analyses_continuation.hpp), compiled
// once here, apart from their other analyses (analyses_<model>.cpp).
#include "delayspec/builtin_analyses.hpp"
#include "delayspec/model_analyses_continuation.hpp"

namespace delayspec {

#define DELAYSPEC_CONTINUATION_OF(Model)                                                                 \
  template ContinuationResult ModelAnalysesFor<Model>::continue_orbit(const AnalysesAt&, const OrbitSettings&, \
                                                                      const ContinuationOptions&) const;   \
  template ContinuationResult ModelAnalysesFor<Model>::continue_period_doubled(                           \
      const AnalysesAt&, const Bifurcation&, const ContinuationOptions&) const;                           \
  template ContinuationResult ModelAnalysesFor<Model>::continue_from_hopf(                                \
      const AnalysesAt&, const EquilibriumBifurcation&, const ContinuationOptions&) const;

DELAYSPEC_CONTINUATION_OF(ImpactModel)
DELAYSPEC_CONTINUATION_OF(LinearModel)
DELAYSPEC_CONTINUATION_OF(MathieuModel)
DELAYSPEC_CONTINUATION_OF(MackeyGlassModel)
DELAYSPEC_CONTINUATION_OF(MillingModel)
DELAYSPEC_CONTINUATION_OF(VariablePitchMillingModel)

}  // namespace delayspec
