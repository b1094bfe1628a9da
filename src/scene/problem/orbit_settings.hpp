#pragma once
// The orbit keys (orbit, orbit_tolerance, orbit_max_periods, orbit_max_iterations,
// orbit_guess_periods, orbit_coarse_N) read into OrbitSettings (delayspec/orbit_search.hpp).
#include "scene/keys/config.hpp"
#include "delayspec/orbit_search.hpp"

namespace delayspec::cli {

OrbitSettings read_orbit_settings(Config& config);

}  // namespace delayspec::cli
