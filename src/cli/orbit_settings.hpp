#pragma once
// Periodic-orbit settings shared by the commands that linearise about an orbit, and the one
// function that finds the orbit (or takes the zero orbit of a linear model).
//
// orbit = simulate: iterate the map from the constant initial history until it settles.
// orbit = newton: simulate orbit_guess_periods maps from the constant initial history, take the
// states of the next map as the guess, then Newton on the discrete periodic problem
// (orbit_newton.hpp): finds unstable orbits too.
#include <string>

#include "config.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/orbit_contacts.hpp"
#include "delayspec/orbit_newton.hpp"
#include "delayspec/orbit_simulation.hpp"

namespace delayspec::cli {

struct OrbitSettings {
  std::string method = "simulate";  // simulate | newton
  OrbitBySimulationOptions simulation;
  OrbitByNewtonOptions newton;
  long guess_periods = 100;  // newton: maps simulated before the guess is taken
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
    zero.method = "zero";
    return zero;
  } else {
    Eigen::VectorXd U = map.constant_history(model.initial_state());
    if (settings.method != "newton") {
      try {
        return orbit_by_simulation(map, U, settings.simulation);
      } catch (const NumericalFailure& e) {
        // The usual cause: the run from the initial history lands on another attractor (the
        // impact model's defaults from rest are chaotic). Say what to do.
        throw NumericalFailure(std::string(e.what()) +
                               ". To reach a periodic orbit: `--set orbit=newton` (Newton on the periodic problem, "
                               "finds unstable orbits too), an initial history near the orbit (x0, v0 for impact), "
                               "or a scene that has one, e.g. data/scenes/default.toml");
      }
    }
    for (long i = 1; i <= settings.guess_periods; ++i) {
      U = map.apply(U);
      if (!U.allFinite())
        throw NumericalFailure("orbit = newton: the simulated guess diverged after " + std::to_string(i) + " periods");
    }
    PeriodicOrbitProblem<Map> problem(map);
    PeriodicOrbit orbit = orbit_by_newton(map, problem.sequence_from_history(U), settings.newton);
    orbit.maps = settings.guess_periods;
    return orbit;
  }
}

// Contacts of the orbit with H = 0, from the states of one map started at its history.
template <class Model, class Map>
ContactSummary orbit_contacts(const Model& model, const Map& map, const PeriodicOrbit& orbit) {
  std::vector<Vec<Model::d>> states;
  map.apply(orbit.history, nullptr, &states);
  states.pop_back();  // u_K = u_0 on a periodic orbit
  return contact_summary(model, states);
}

}  // namespace delayspec::cli
