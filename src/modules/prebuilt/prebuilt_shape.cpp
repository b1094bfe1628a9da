// The analyses of FunctionModel<kPrebuiltShapes[DELAYSPEC_SHAPE_INDEX]> (function_model.hpp),
// compiled once: CMakeLists.txt builds this file once per shape of prebuilt_shapes.hpp.
#include "delayspec/function_model.hpp"
#include "delayspec/model_analyses.hpp"
#include "delayspec/model_analyses_continuation.hpp"
#include "delayspec/prebuilt_shapes.hpp"
#include "modules/prebuilt/prebuilt_analyses.hpp"

namespace delayspec::detail {

template <>
ModelAnalyses* prebuilt_shape_analyses<DELAYSPEC_SHAPE_INDEX>(const ModelFunctions& functions,
                                                              const ModelValues& values) {
  using Model = FunctionModel<kPrebuiltShapes[DELAYSPEC_SHAPE_INDEX]>;
  static_assert(DelayModel<Model>);
  return new ModelAnalysesFor<Model>(Model(functions, values));
}

}  // namespace delayspec::detail
