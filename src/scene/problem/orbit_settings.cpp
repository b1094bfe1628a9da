#include "scene/problem/orbit_settings.hpp"

namespace delayspec::cli {

OrbitSettings read_orbit_settings(Config& config) {
  OrbitSettings s;
  std::vector<std::pair<std::string, OrbitMethod>> methods;
  for (OrbitMethod m : {OrbitMethod::automatic, OrbitMethod::shooting, OrbitMethod::simulate, OrbitMethod::newton})
    methods.emplace_back(to_string(m), m);
  s.method = config.get_enum("orbit", s.method, methods);
  s.simulation.tolerance = config.get_double("orbit_tolerance", s.simulation.tolerance);
  require_positive("orbit_tolerance", s.simulation.tolerance);
  s.newton.tolerance = s.simulation.tolerance;
  s.shooting.tolerance = s.simulation.tolerance;
  s.simulation.max_maps = config.get_int_in_range("orbit_max_periods", s.simulation.max_maps, 1, 1'000'000'000);
  s.newton.max_iterations =
      static_cast<int>(config.get_int_in_range("orbit_max_iterations", s.newton.max_iterations, 1, 10000));
  s.shooting.max_iterations = s.newton.max_iterations;
  s.guess_periods = config.get_int_in_range("orbit_guess_periods", s.guess_periods, 0, 100'000'000);
  s.coarse_N = static_cast<int>(config.get_int_in_range("orbit_coarse_N", s.coarse_N, 1, 10'000'000));
  return s;
}

}  // namespace delayspec::cli
