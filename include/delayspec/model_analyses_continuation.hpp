#pragma once
// ModelAnalysesFor's continuation (model_analyses.hpp), defined apart from the other analyses:
// included where it is instantiated (DELAYSPEC_INSTANTIATE_CONTINUATION below: for the built-in
// models src/engine/analyses_continuation.cpp and src/modules/models/models_continuation.cpp) and
// into the object compiled from a scene's equations (equation_plugin.cpp), never into the unit of
// the stepper's analyses, whose inlining it would share.
#include <functional>
#include <memory>
#include <stdexcept>

#include "delayspec/continuation.hpp"
#include "delayspec/hopf_branch.hpp"
#include "delayspec/model_analyses.hpp"

namespace delayspec {

namespace detail {
// The family `at` as continuation takes it: p -> the Model at p.
template <class Model>
std::function<Model(double)> model_at(const AnalysesAt& at) {
  return [at](double p) {
    const std::shared_ptr<const ModelAnalyses> analyses = at(p);
    const auto* typed = dynamic_cast<const ModelAnalysesFor<Model>*>(analyses.get());
    if (!typed) throw std::logic_error("continuation: the model at another parameter is of another type");
    return typed->model();
  };
}
}  // namespace detail

template <class Model>
ContinuationResult ModelAnalysesFor<Model>::continue_orbit(const AnalysesAt& at, const OrbitSettings& settings,
                                                           const ContinuationOptions& options) const {
  const StroboscopicMap<Model> map(TrapezoidStepper<Model>(model_, options.step_options),
                                   model_grid(model_, options.N, options.periods_per_map, options.step_options.grid));
  const PeriodicOrbit orbit = find_orbit(model_, map, settings);
  const Eigen::VectorXd guess = PeriodicOrbitProblem<StroboscopicMap<Model>>(map).sequence_from_history(orbit.history);
  return delayspec::continue_orbit<Model>(detail::model_at<Model>(at), guess, options);
}

template <class Model>
ContinuationResult ModelAnalysesFor<Model>::continue_period_doubled(const AnalysesAt& at, const Bifurcation& at_pd,
                                                                    const ContinuationOptions& options) const {
  return delayspec::continue_period_doubled<Model>(detail::model_at<Model>(at), at_pd, options);
}

template <class Model>
ContinuationResult ModelAnalysesFor<Model>::continue_from_hopf(const AnalysesAt& at, const EquilibriumBifurcation& hopf,
                                                               const ContinuationOptions& options) const {
  if constexpr (AutonomousModel<Model> && !Model::is_linear) {
    return delayspec::continue_from_hopf<Model>(detail::model_at<Model>(at), hopf, options);
  } else if constexpr (AutonomousModel<Model>) {
    throw BadInput("a linear model has no isolated periodic orbits: its Hopf points start no branch of orbits");
  } else {
    throw BadInput(kNotAutonomous);
  }
}

template <class Model>
ContinuationResult ModelAnalysesFor<Model>::continue_autonomous_orbit(const AnalysesAt& at,
                                                                      const AutonomousOrbitOptions& orbit,
                                                                      const ContinuationOptions& options) const {
  if constexpr (AutonomousModel<Model> && !Model::is_linear) {
    if (orbit.N != options.N)
      throw BadInput("continue_autonomous_orbit: the orbit's N (" + std::to_string(orbit.N) +
                     ") differs from the branch's (" + std::to_string(options.N) + ")");
    return delayspec::continue_autonomous_orbit<Model>(detail::model_at<Model>(at), autonomous_orbit(orbit).orbit,
                                                       options);
  } else if constexpr (AutonomousModel<Model>) {
    throw BadInput("a linear model has no isolated periodic orbits to continue");
  } else {
    throw BadInput(kNotAutonomous);
  }
}

}  // namespace delayspec

// The explicit instantiation of Model's continuation, beside `template class ModelAnalysesFor<Model>`
// in a unit of its own.
#define DELAYSPEC_INSTANTIATE_CONTINUATION(Model)                                                          \
  template ContinuationResult ModelAnalysesFor<Model>::continue_orbit(const AnalysesAt&, const OrbitSettings&, \
                                                                      const ContinuationOptions&) const;   \
  template ContinuationResult ModelAnalysesFor<Model>::continue_period_doubled(                           \
      const AnalysesAt&, const Bifurcation&, const ContinuationOptions&) const;                           \
  template ContinuationResult ModelAnalysesFor<Model>::continue_from_hopf(                                \
      const AnalysesAt&, const EquilibriumBifurcation&, const ContinuationOptions&) const;                 \
  template ContinuationResult ModelAnalysesFor<Model>::continue_autonomous_orbit(                         \
      const AnalysesAt&, const AutonomousOrbitOptions&, const ContinuationOptions&) const;
