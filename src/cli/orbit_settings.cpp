#include "orbit_settings.hpp"

namespace delayspec::cli {

OrbitSettings read_orbit_settings(Config& config) {
  OrbitSettings s;
  s.method = config.get_choice("orbit", s.method, {"simulate", "newton"});
  s.simulation.tolerance = config.get_double("orbit_tolerance", s.simulation.tolerance);
  require_positive("orbit_tolerance", s.simulation.tolerance);
  s.simulation.max_maps = config.get_int("orbit_max_periods", s.simulation.max_maps);
  if (s.simulation.max_maps < 1)
    throw BadInput("`orbit_max_periods = " + std::to_string(s.simulation.max_maps) + "`: must be >= 1");
  return s;
}

}  // namespace delayspec::cli
