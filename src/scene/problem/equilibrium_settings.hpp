#pragma once
// The keys of `equilibrium` (docs/cli.md): nroots, equilibrium_guess, equilibrium_tolerance and
// the eigensolver keys but nev (its nev follows from nroots).
#include <Eigen/Core>

#include "delayspec/equilibrium.hpp"
#include "scene/keys/config.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

struct EquilibriumSettings {
  EquilibriumOptions options;
  Eigen::VectorXd guess;  // d entries, or empty: the model's constant initial history
};

// BadInput naming the key: nroots outside 1..1000, a guess whose length is not the state's d, a
// tolerance that is not in (0, 1e-3].
EquilibriumSettings read_equilibrium_settings(Config& config, const Problem& problem);

// BadInput "`model = NAME` is not autonomous: ..." unless the problem's model is (model.hpp).
void require_autonomous(const Problem& problem);

}  // namespace delayspec::cli
