#pragma once
// Periodic orbit by simulation: iterate the stroboscopic map from a starting history until
// it settles, |P(U) - U|_inf <= tolerance (1 + |U|_inf). Works for stable orbits only; an
// unstable orbit or a chaotic attractor ends in NumericalFailure with the last residual.
#include <cmath>
#include <string>

#include "delayspec/errors.hpp"
#include "delayspec/periodic_orbit.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec {

struct OrbitBySimulationOptions {
  double tolerance = 1e-12;  // relative sup-norm residual to accept
  long max_maps = 20000;     // applications of the stroboscopic map before giving up
};

// The guess Newton starts from: U after `periods` maps. NumericalFailure "WHO: the simulated guess
// diverged after i periods" at the first map whose result is not finite (an attractor at infinity,
// or the impact model's chaotic transient blown up by a large step).
template <class Map>
Eigen::VectorXd simulated_guess(const Map& map, Eigen::VectorXd U, long periods, const std::string& who) {
  for (long i = 1; i <= periods; ++i) {
    U = map.apply(U);
    if (!U.allFinite())
      throw NumericalFailure(who + ": the simulated guess diverged after " + std::to_string(i) + " periods");
  }
  return U;
}

template <class Map>
PeriodicOrbit orbit_by_simulation(const Map& map, Eigen::VectorXd U, const OrbitBySimulationOptions& opt = {}) {
  if (!(opt.tolerance > 0)) throw BadInput("`orbit_tolerance = " + format_number(opt.tolerance) + "`: must be > 0");
  if (opt.max_maps < 1) throw BadInput("`orbit_max_periods = " + std::to_string(opt.max_maps) + "`: must be >= 1");
  PeriodicOrbit orbit;
  for (long i = 1; i <= opt.max_maps; ++i) {
    Eigen::VectorXd next = map.apply(U);
    const double residual = (next - U).lpNorm<Eigen::Infinity>();
    const double scale = 1 + next.lpNorm<Eigen::Infinity>();
    if (!std::isfinite(residual))
      throw NumericalFailure("orbit by simulation: the trajectory diverged after " + std::to_string(i) + " periods");
    U.swap(next);
    orbit.residual = residual;
    orbit.maps = i;
    if (residual <= opt.tolerance * scale) {
      orbit.history = U;
      return orbit;
    }
  }
  throw NumericalFailure("orbit by simulation: not settled after " + std::to_string(opt.max_maps) +
                         " periods, |P(U) - U| = " + format_number(orbit.residual) +
                         " (unstable or not periodic? try orbit = newton or more periods)");
}

}  // namespace delayspec
