#include "scene/problem/models_module_loader.hpp"

#include <string>
#include <type_traits>
#include <variant>

#include "delayspec/builtin_analyses.hpp"
#include "scene/loading/module_loader.hpp"

namespace delayspec::cli {

const ModelsModule& models_module(const std::string& model_name) {
  // A function-local static: initialised once, under the compiler's lock; a failed load throws
  // (naming the model that needed the module) and is tried again at the next call.
  static const ModelsModule& module = load_module<ModelsModule>(
      module_file(models_module_file), models_module_symbol,
      ModuleDescription{"model = " + model_name, "the analyses of the built-in models but the impact model's",
                        "libdelayspec alone"});
  return module;
}

std::shared_ptr<const ModelAnalyses> builtin_model_analyses(const AnyModel& model) {
  return std::visit(
      [](const auto& m) -> std::shared_ptr<const ModelAnalyses> {
        using M = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<M, ImpactModel>) return builtin_analyses(m);  // in the library
        else if constexpr (std::is_same_v<M, LinearModel>) return models_module("linear").linear(m);
        else if constexpr (std::is_same_v<M, MathieuModel>) return models_module("mathieu").mathieu(m);
        else if constexpr (std::is_same_v<M, MackeyGlassModel>) return models_module("mackey-glass").mackey_glass(m);
        else if constexpr (std::is_same_v<M, MillingModel>) return models_module("milling").milling(m);
        else {
          static_assert(std::is_same_v<M, VariablePitchMillingModel>, "a built-in model without its analyses");
          return models_module("milling").milling_variable_pitch(m);
        }
      },
      model);
}

ClassicResult builtin_classic_multipliers(const Problem& problem, int m, ClassicMethod method, int nev) {
  if (!problem.model) throw BadInput("the classic discretisations take the built-in models only, not model = equations");
  return models_module(problem.model_name).classic(*problem.model, m, method, nev);
}

}  // namespace delayspec::cli
