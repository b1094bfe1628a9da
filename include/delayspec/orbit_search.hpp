#pragma once
// How a periodic orbit is found (OrbitSettings), the one function that finds it (or takes the
// zero orbit of a linear model), and the orbit's contacts with the switching surface.
//
// orbit = auto (default): nested iteration (orbit_shooting.hpp): levels N, N/8, ... down to the
//   last one >= orbit_coarse_N, then orbit_coarse_N itself unless it exceeds half the last; at
//   the coarsest, orbit_guess_periods maps simulated from the constant initial history and
//   Newton-Krylov shooting, or sparse-LU Newton from the same guess if shooting fails; every
//   finer level by shooting from the coarser orbit. With N < 2 orbit_coarse_N there is one
//   level, N itself. Finds unstable orbits too.
// orbit = shooting: the same levels, shooting only (no sparse-LU fallback).
// orbit = simulate: iterate the map from the constant initial history until it settles.
// orbit = newton: simulate orbit_guess_periods maps from the constant initial history, then
//   Newton on the discrete periodic problem at N (orbit_newton.hpp, sparse LU).
#include <string>

#include "delayspec/detail/cubic_hermite.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/orbit_contacts.hpp"
#include "delayspec/orbit_newton.hpp"
#include "delayspec/orbit_shooting.hpp"
#include "delayspec/orbit_simulation.hpp"

namespace delayspec {

// How find_orbit looks for the orbit (the header's list).
enum class OrbitMethod { automatic, shooting, simulate, newton };
// "auto", "shooting", "simulate", "newton".
inline std::string to_string(OrbitMethod method) {
  switch (method) {
    case OrbitMethod::automatic: return "auto";
    case OrbitMethod::shooting: return "shooting";
    case OrbitMethod::simulate: return "simulate";
    case OrbitMethod::newton: return "newton";
  }
  return "?";
}

struct OrbitSettings {
  OrbitMethod method = OrbitMethod::automatic;
  OrbitBySimulationOptions simulation;
  OrbitByNewtonOptions newton;
  OrbitByShootingOptions shooting;
  long guess_periods = 100;  // newton, auto, shooting: maps simulated before the guess is taken
  int coarse_N = 64;         // auto, shooting: the coarsest level is the last N / 8^i >= coarse_N
};

// The periodic orbit of `map` for the model's constant initial history; for a linear model the
// zero orbit (its monodromy does not depend on the orbit). `at_orbit`, when given, receives the
// step maps and states of one map at the orbit's history (the monodromy and the trajectory at
// the orbit), from the orbit search's own last evaluation where it has one.
template <class Model, class Map>
PeriodicOrbit find_orbit(const Model& model, const Map& map, const OrbitSettings& settings,
                         OrbitLinearisation<Model::d, delayed_rows<Model>>* at_orbit = nullptr) {
  auto linearise = [&](PeriodicOrbit orbit) {
    if (at_orbit) map.apply(orbit.history, &at_orbit->maps, &at_orbit->states);
    return orbit;
  };
  if constexpr (Model::is_linear) {
    PeriodicOrbit zero;
    zero.history = Eigen::VectorXd::Zero(map.dimension());
    zero.residual = 0;
    zero.method = OrbitFoundBy::zero;
    return linearise(std::move(zero));
  } else {
    if (settings.method == OrbitMethod::automatic || settings.method == OrbitMethod::shooting) {
      NestedShootingOptions o;
      o.shooting = settings.shooting;
      o.newton = settings.newton;
      o.coarse_method =
          settings.method == OrbitMethod::automatic ? CoarseOrbitMethod::automatic : CoarseOrbitMethod::shooting;
      o.guess_periods = settings.guess_periods;
      o.coarse_N = settings.coarse_N;
      return orbit_by_nested_shooting(map, model.initial_state(), o, at_orbit);
    }
    Eigen::VectorXd U = map.constant_history(model.initial_state());
    if (settings.method == OrbitMethod::simulate) {
      try {
        return linearise(orbit_by_simulation(map, U, settings.simulation));
      } catch (const NumericalFailure& e) {
        // The usual cause: the run from the initial history lands on another attractor (the
        // impact model's defaults from rest are chaotic). Say what to do.
        throw NumericalFailure(std::string(e.what()) +
                               ". To reach a periodic orbit: `--set orbit=auto` or `--set orbit=newton` (Newton on "
                               "the periodic problem, finds unstable orbits too), an initial history near the orbit "
                               "(x0, v0 for impact), or a scene that has one, e.g. data/scenes/default.toml");
      }
    }
    // OrbitMethod::newton
    U = simulated_guess(map, std::move(U), settings.guess_periods, "orbit = newton");
    PeriodicOrbitProblem<Map> problem(map);
    PeriodicOrbit orbit = orbit_by_newton(map, problem.sequence_from_history(U), settings.newton);
    orbit.maps = settings.guess_periods;
    return linearise(std::move(orbit));
  }
}

// Contacts of the orbit with H = 0, from the states of one map at the orbit (u_0 .. u_K): the runs
// of grid nodes in region 1 (contact_summary), and, between two nodes outside it, a contact that
// starts and ends inside the step (shorter than a step: near grazing at coarse N), seen by the
// cubic Hermite interpolant of H(y(t)) with the slopes dH/dt = grad H . f at the step's nodes
// (H affine, model.hpp; continuation's max H, periodic_branch.hpp): counted as a contact, and
// every step's largest interpolated H in max_H. The delayed states from the grid's taps, the
// orbit repeated periodically into the past.
template <class Model, class Stepper>
ContactSummary orbit_contacts(const StroboscopicMap<Model, Stepper>& map, std::vector<Vec<Model::d>> states) {
  using V = Vec<Model::d>;
  const Model& model = map.stepper().model();
  states.pop_back();  // u_K = u_0 on a periodic orbit
  ContactSummary s = contact_summary(model, states);
  if constexpr (Model::has_switching) {
    const HistoryGrid& g = map.grid();
    const long K = static_cast<long>(states.size()), M = g.M;
    const auto u = [&](long l) { return states[static_cast<size_t>(((l % K) + K) % K)]; };
    const auto slot = [&](long i) { return u(i - M); };
    const int fixed = map.stepper().options().fixed_region;  // one field throughout (step_options.hpp)
    const auto region = [&](const V& y) { return fixed != 0 ? fixed : region_of(model, y); };
    for (long l = 0; l < K; ++l) {
      const auto [w0, w1, t, h] = g.template delay_taps<Model::d, DelayedVec<Model>>(l, slot);
      const V a = u(l), b = u(l + 1);
      const double Ha = model.H(a), Hb = model.H(b);
      const V grad = model.grad_H(a);
      const double top = detail::hermite_maximum(Ha, Hb, grad.dot(model.f(region(a), t, a, w0)),
                                                 grad.dot(model.f(region(b), t + h, b, w1)), h);
      s.max_H = std::max(s.max_H, top);
      if (!(Ha > 0) && !(Hb > 0) && top > 0) {
        ++s.contacts;
        ++s.steps_with_inner_contact;
      }
    }
  }
  return s;
}

}  // namespace delayspec
