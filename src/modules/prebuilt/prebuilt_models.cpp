// prebuilt_model_analyses (model_functions.hpp): the shape looked up in kPrebuiltShapes; and the
// library's build, which a model's loader checks.
#include <iterator>
#include <utility>

#include "delayspec/model_functions.hpp"
#include "delayspec/prebuilt_shapes.hpp"
#include "delayspec/version.hpp"
#include "modules/prebuilt/prebuilt_analyses.hpp"

namespace delayspec {

// CMakeLists.txt builds one unit per line of the list; this fails when the two disagree.
static_assert(std::size(kPrebuiltShapes) == DELAYSPEC_PREBUILT_SHAPE_COUNT,
              "CMakeLists.txt counted another number of prebuilt shapes than prebuilt_shapes.hpp holds");

namespace {
template <int... I>
ModelAnalyses* analyses_of_shape(const ModelShape& shape, const ModelFunctions& functions, const ModelValues& values,
                                 std::integer_sequence<int, I...>) {
  ModelAnalyses* out = nullptr;
  ((out = shape == kPrebuiltShapes[I] ? detail::prebuilt_shape_analyses<I>(functions, values) : nullptr) || ...);
  return out;
}
}  // namespace

ModelAnalyses* prebuilt_model_analyses(const ModelShape& shape, const ModelFunctions& functions,
                                       const ModelValues& values) {
  return analyses_of_shape(shape, functions, values,
                           std::make_integer_sequence<int, static_cast<int>(std::size(kPrebuiltShapes))>());
}

const char* prebuilt_library_build() { return DELAYSPEC_VERSION " " DELAYSPEC_REVISION; }

}  // namespace delayspec
