#include "orbit_settings.hpp"

namespace delayspec::cli {

OrbitSettings read_orbit_settings(Config& config) {
  OrbitSettings s;
  s.method = config.get_choice("orbit", s.method, {"simulate", "newton"});
  s.simulation.tolerance = config.get_double("orbit_tolerance", s.simulation.tolerance);
  require_positive("orbit_tolerance", s.simulation.tolerance);
  s.newton.tolerance = s.simulation.tolerance;
  s.simulation.max_maps = config.get_int("orbit_max_periods", s.simulation.max_maps);
  if (s.simulation.max_maps < 1)
    throw BadInput("`orbit_max_periods = " + std::to_string(s.simulation.max_maps) + "`: must be >= 1");
  const long iterations = config.get_int("orbit_max_iterations", s.newton.max_iterations);
  if (iterations < 1 || iterations > 10000)
    throw BadInput("`orbit_max_iterations = " + std::to_string(iterations) + "`: must be between 1 and 10000");
  s.newton.max_iterations = static_cast<int>(iterations);
  s.guess_periods = config.get_int("orbit_guess_periods", s.guess_periods);
  if (s.guess_periods < 0 || s.guess_periods > 100000000)
    throw BadInput("`orbit_guess_periods = " + std::to_string(s.guess_periods) + "`: must be between 0 and 1e8");
  return s;
}

}  // namespace delayspec::cli
