#pragma once
// The analyses of the built-in models (model_analyses.hpp), compiled once: builtin_analyses(model)
// wraps a model in them. The impact model's (the default scene's) are in the library
// (src/engine/analyses_impact.cpp); the other five models' in libdelayspec_models
// (src/modules/models/models_module.hpp; the CMake package's delayspec::models), which a program
// or test that names them links, and
// which the scene layer loads on first use, so that the program prints its first number without
// waiting for their compilation (issue 37; docs/benchmarks.md, "Build time").
#include <memory>

#include "delayspec/model_analyses.hpp"
#include "delayspec/model_impact.hpp"
#include "delayspec/model_linear.hpp"
#include "delayspec/model_mackey_glass.hpp"
#include "delayspec/model_mathieu.hpp"
#include "delayspec/model_milling.hpp"
#include "delayspec/model_milling_variable_pitch.hpp"

namespace delayspec {

extern template class ModelAnalysesFor<ImpactModel>;
extern template class ModelAnalysesFor<LinearModel>;
extern template class ModelAnalysesFor<MathieuModel>;
extern template class ModelAnalysesFor<MackeyGlassModel>;
extern template class ModelAnalysesFor<MillingModel>;
extern template class ModelAnalysesFor<VariablePitchMillingModel>;

template <class Model>
std::shared_ptr<const ModelAnalyses> builtin_analyses(const Model& model) {
  return std::make_shared<const ModelAnalysesFor<Model>>(model);
}

}  // namespace delayspec
