#pragma once
// The analyses of the I-th prebuilt shape (prebuilt_shapes.hpp), one unit each
// (prebuilt_shape.cpp), and the lookup of a shape among them (prebuilt_models.cpp).
#include "delayspec/model_functions.hpp"

namespace delayspec::detail {

template <int I>
ModelAnalyses* prebuilt_shape_analyses(const ModelFunctions& functions, const ModelValues& values);

}  // namespace delayspec::detail
