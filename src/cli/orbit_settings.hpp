#pragma once
// Periodic-orbit settings shared by the commands that linearise about an orbit, and the one
// function that finds the orbit (or takes the zero orbit of a linear model).
#include <string>

#include "config.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/orbit_simulation.hpp"

namespace delayspec::cli {

struct OrbitSettings {
  std::string method = "simulate";  // simulate | newton
  OrbitBySimulationOptions simulation;
};

OrbitSettings read_orbit_settings(Config& config);

// The periodic orbit of `map` for the model's constant initial history; for a linear model the
// zero orbit (its monodromy does not depend on the orbit).
template <class Model, class Map>
PeriodicOrbit find_orbit(const Model& model, const Map& map, const OrbitSettings& settings) {
  if constexpr (Model::is_linear) {
    PeriodicOrbit zero;
    zero.history = Eigen::VectorXd::Zero(map.dimension());
    zero.residual = 0;
    return zero;
  } else {
    if (settings.method == "newton")
      throw BadInput("`orbit = newton`: not available yet; use orbit = simulate");
    return orbit_by_simulation(map, map.constant_history(model.initial_state()), settings.simulation);
  }
}

}  // namespace delayspec::cli
