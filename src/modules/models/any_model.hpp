#pragma once
// AnyModel: a built-in model with its parameters (scene/problem/problem.hpp reads it from the
// keys). Here, below the scene layer, so that libdelayspec_models (models_module.hpp) can take it.
#include <variant>

#include "delayspec/model_impact.hpp"
#include "delayspec/model_linear.hpp"
#include "delayspec/model_mackey_glass.hpp"
#include "delayspec/model_mathieu.hpp"
#include "delayspec/model_milling.hpp"
#include "delayspec/model_milling_variable_pitch.hpp"

namespace delayspec::cli {

using AnyModel =
    std::variant<ImpactModel, LinearModel, MathieuModel, MackeyGlassModel, MillingModel, VariablePitchMillingModel>;

}  // namespace delayspec::cli
