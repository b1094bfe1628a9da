#pragma once
// The eigen-solver keys shared by every command that computes Floquet multipliers:
// nev, solver, ncv, tol, max_restarts, seed (README "Keys"; CLI contract for nev and solver).
#include "scene/keys/config.hpp"
#include "delayspec/floquet.hpp"

namespace delayspec::cli {

// Reads the keys above (defaults: FloquetOptions' defaults, nev = default_nev). BadInput names
// the key and value: nev < 1, unknown solver, ncv < 0, tol <= 0 or not finite, max_restarts < 0,
// seed < 0. Bounds that depend on the dimension are checked by floquet_multipliers().
FloquetOptions read_floquet_options(Config& config, int default_nev = 6);
// The same keys but nev (for an analysis that sets how many it needs: equilibrium's roots).
FloquetOptions read_eigensolver_options(Config& config);

}  // namespace delayspec::cli
