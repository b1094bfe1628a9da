#pragma once
// `delayspec continue` with continue_object = equilibrium: the branch of equilibria of an
// autonomous model in continue_key, with its fold and Hopf points (equilibrium_branch.hpp;
// docs/continuation.md). Called by command_continue.
#include "scene/keys/config.hpp"
#include "scene/output/invocation.hpp"

namespace delayspec::cli {

// Reads continue's range and step keys and equilibrium's keys (nroots, equilibrium_guess,
// equilibrium_tolerance, the eigensolver's). With continue_switch = true it also follows the
// branch of orbits born at each Hopf point (hopf_branch.hpp) at every N of continue_Ns, and reads
// nev and orbit_tolerance for them. BadInput for continue_Ns without continue_switch (an
// equilibrium's bifurcations carry no discretisation error) and for a model that is not
// autonomous. Files with --out DIR: equilibria.csv, equilibrium_bifurcations.csv, with
// continue_switch hopf_branch_K.csv and hopf_bifurcations_K.csv (K = 1, 2, ... by the Hopf
// points' order on the branch, in branch.csv's and bifurcations.csv's formats, plus the period),
// continue.json. Exit 3 after writing a branch that ended in a failure.
int continue_equilibria(Config& config, const Invocation& inv);

}  // namespace delayspec::cli
