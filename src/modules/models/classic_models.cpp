// The classic dense discretisations (sdm0, fdm1: delayspec/classic_discretisation.hpp) of the
// built-in models, for `bench` (models_module.hpp). Instantiated for every model: for one they do
// not take (the impact and Mackey-Glass models are not linear) classic_monodromy compiles to its
// BadInput alone.
#include <type_traits>
#include <variant>

#include "delayspec/classic_discretisation.hpp"
#include "modules/models/models_module.hpp"

namespace delayspec::cli {

ClassicResult classic_multipliers_of(const AnyModel& model, int m, ClassicMethod method, int nev) {
  return std::visit([&](const auto& any) { return classic_multipliers(any, m, method, nev); }, model);
}

}  // namespace delayspec::cli
