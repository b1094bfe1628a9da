#pragma once
// delayspec boundary with boundary_object = equilibrium: the Hopf curves of an autonomous model's
// equilibrium in two parameters, with the criticality along them and the generalised Hopf points
// (equilibrium_boundary.hpp; docs/autonomous.md).
#include "scene/keys/config.hpp"
#include "scene/output/invocation.hpp"

namespace delayspec::cli {

int boundary_equilibria(Config& config, const Invocation& inv);

}  // namespace delayspec::cli
