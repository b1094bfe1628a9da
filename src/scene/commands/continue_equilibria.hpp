#pragma once
// `delayspec continue` with continue_object = equilibrium: the branch of equilibria of an
// autonomous model in continue_key, with its fold and Hopf points (equilibrium_branch.hpp;
// docs/continuation.md). Called by command_continue.
#include "scene/keys/config.hpp"
#include "scene/output/invocation.hpp"

namespace delayspec::cli {

// Reads continue's range and step keys and equilibrium's keys (nroots, equilibrium_guess,
// equilibrium_tolerance, the eigensolver's); BadInput for continue_Ns or continue_switch (an
// equilibrium's bifurcations carry no discretisation error; the orbits born at a Hopf point are
// not followed yet) and for a model that is not autonomous. Files with --out DIR: equilibria.csv,
// equilibrium_bifurcations.csv, continue.json. Exit 3 after writing a branch that ended in a failure.
int continue_equilibria(Config& config, const Invocation& inv);

}  // namespace delayspec::cli
