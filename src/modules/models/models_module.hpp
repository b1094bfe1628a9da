#pragma once
// The analyses of the built-in models other than the impact model (linear, mathieu, mackey-glass,
// milling with equal and variable pitch: analyses_<model>.cpp, models_continuation.cpp), and the
// classic discretisations of every built-in model (classic_models.cpp), are a
// shared module of their own, libdelayspec_models.so, which the scene layer loads with dlopen the
// first time a scene names one of these models (src/scene/problem/models_module_loader.hpp). Their
// templates take some 70 s of CPU to compile; in the library they delayed the program, whose
// default scene needs only the impact model, by about a third of its build (docs/benchmarks.md,
// "Build time").
//
// The module exports one C symbol, models_module_symbol, a function that returns this table.
// Its members have C++ types: the module and the program must come from one build, which the
// loader checks with `version`. The tests and programs against the installed package
// (delayspec::models) that name these models link the module directly.
#include <memory>

#include "delayspec/classic_result.hpp"
#include "delayspec/model_analyses.hpp"
#include "modules/models/any_model.hpp"

namespace delayspec::cli {

struct ModelsModule {
  // DELAYSPEC_VERSION " " DELAYSPEC_REVISION of the module's build (delayspec/version.hpp).
  const char* version = nullptr;
  // builtin_analyses (delayspec/builtin_analyses.hpp) of each model.
  std::shared_ptr<const ModelAnalyses> (*linear)(const LinearModel&) = nullptr;
  std::shared_ptr<const ModelAnalyses> (*mathieu)(const MathieuModel&) = nullptr;
  std::shared_ptr<const ModelAnalyses> (*mackey_glass)(const MackeyGlassModel&) = nullptr;
  std::shared_ptr<const ModelAnalyses> (*milling)(const MillingModel&) = nullptr;
  std::shared_ptr<const ModelAnalyses> (*milling_variable_pitch)(const VariablePitchMillingModel&) = nullptr;
  // The classic dense discretisations of `bench` (sdm0, fdm1: classic_multipliers_of below), here
  // rather than in the scene layer, whose first unity batch took 48 s to compile with them and 34
  // without (their matrix exponentials and dense products, compiled for each linear model).
  ClassicResult (*classic)(const AnyModel& model, int m, ClassicMethod method, int nev) = nullptr;
};

// classic_multipliers (delayspec/classic_discretisation.hpp) of the model, any built-in one:
// BadInput for a model they do not take (nonlinear, several delays, tau != T) or m < 2.
ClassicResult classic_multipliers_of(const AnyModel& model, int m, ClassicMethod method, int nev);

// The module's file name, beside libdelayspec (build tree and installed alike).
inline constexpr char models_module_file[] = "libdelayspec_models.so";
// extern "C" const ModelsModule* delayspec_models_module(): the table, static in the module.
inline constexpr char models_module_symbol[] = "delayspec_models_module";

}  // namespace delayspec::cli
