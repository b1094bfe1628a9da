#pragma once
// The branch of periodic orbits born at a Hopf point of an equilibrium (issue 35, item 4).
//
// At a Hopf point (p_H, y*) a pair of characteristic roots is +-i omega (equilibrium_branch.hpp)
// and Delta(i omega) c = 0 (equilibrium.hpp). Near it the orbits are, to first order in their
// amplitude a,
//
//   y(t) = y* + a Re(c e^{i omega t}),   period 2 pi / omega,   p - p_H = O(a^2),
//
// so the branch of orbits (x, T, p) (autonomous_branch.hpp: the orbit on its own time scale, K
// states, its period, the parameter) leaves the equilibrium, seen as the orbit x = (y*, ..., y*)
// of period T_0 = 2 pi / omega, along the tangent (v, 0, 0) with v_l = Re(c e^{2 pi i l / K}):
// the amplitude changes at first order, the period and the parameter at second. The tracer
// (continuation_branch.hpp) starts at that point with that tangent, without Newton there (the
// equilibrium solves the orbit problem for every T: its Jacobian is singular); the first step's
// corrector lands on the discrete branch, whose Hopf point differs from the exact one by the
// discretisation's O(h^2). Then pseudo-arclength as for forced orbits, with the same detection
// and location of folds, period doublings and Neimark-Sacker points (continuation.hpp) among
// the multipliers other than the trivial one; the segment leaving the Hopf point is not searched
// (its multiplier pair at 1 is the Hopf point itself).
//
// K = round(N T_0 / tau_max) at p_H, fixed along the branch: N steps per the longest delay at the
// Hopf point (a branch whose period grows has fewer steps per delay further on; the scene layer's
// continue_Ns gives each bifurcation its error bar).
//
// BadInput: omega <= 0, a state of the wrong size, a model that is not autonomous or is linear
// (a linear model's Hopf point has a continuum of orbits, none isolated).
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "delayspec/autonomous_orbit.hpp"
#include "delayspec/continuation.hpp"
#include "delayspec/equilibrium.hpp"
#include "delayspec/equilibrium_branch.hpp"
#include "delayspec/detail/autonomous_branch.hpp"

namespace delayspec {

// The branch of orbits from the Hopf point `hopf` (type hopf, from continue_equilibrium) of the
// family model_at (double -> Model), on the discretisation of options.N, within [from, to] of
// the options (either end).
template <class Model, class ModelAt>
ContinuationResult continue_from_hopf(const ModelAt& model_at, const EquilibriumBifurcation& hopf,
                                      const ContinuationOptions& options) {
  static_assert(AutonomousModel<Model>, "a Hopf point needs an autonomous model (model.hpp)");
  constexpr int D = Model::d;
  if (hopf.type != EquilibriumBifurcationType::hopf || !(hopf.omega > 0) || !std::isfinite(hopf.omega))
    throw BadInput("continue_from_hopf: needs a located Hopf point with omega > 0 (omega = " +
                   format_number(hopf.omega) + ")");
  if (hopf.state.size() != D)
    throw BadInput("continue_from_hopf: the equilibrium has " + std::to_string(hopf.state.size()) +
                   " entries, expected " + std::to_string(D));
  const Model model = model_at(hopf.parameter);
  const double T0 = 2 * std::numbers::pi / hopf.omega;
  AutonomousOrbitOptions grid_of;  // K = round(N T0 / tau_max), as an orbit of unknown period lays it
  grid_of.period_guess = T0;
  grid_of.N = options.N;
  const int K = autonomous_steps_per_period(model, grid_of);
  // c: Delta(i omega) c = 0 (the SVD in the library: compiled once, not per model)
  const Eigen::VectorXcd c =
      constant_history(model, Vec<D>(hopf.state)).null_vector(std::complex<double>(0, hopf.omega));
  const long n = static_cast<long>(D) * K;
  Eigen::VectorXd start(n + 1), tangent = Eigen::VectorXd::Zero(n + 2);  // (x, T), (x, T, p)
  for (long l = 0; l < K; ++l) {
    const std::complex<double> phase = std::polar(1.0, 2 * std::numbers::pi * static_cast<double>(l) / K);
    start.segment<D>(D * l) = hopf.state;
    tangent.segment<D>(D * l) = (c * phase).real();
  }
  start[n] = T0;
  const ContinuationOptions o = continuation_detail::checked_options(options);
  const continuation_detail::AutonomousBranch<Model, ModelAt> branch(model_at, K, o);
  return continuation_detail::trace_branch(branch, start, o, &tangent, hopf.parameter);
}

// The branch of orbits of unknown period through `orbit` (autonomous_orbit.hpp: found at
// p = options.from, on its grid of K steps per period), followed in p as the branch from a Hopf
// point is (K fixed along it): Newton at `from` from (the orbit's sequence, its period) with the
// phase condition, then pseudo-arclength with the same detection and location of folds, period
// doublings and Neimark-Sacker points among the multipliers other than the trivial one (issue 60,
// item 5: an orbit found by `floquet` with period_guess, continued from there).
template <class Model, class ModelAt>
ContinuationResult continue_autonomous_orbit(const ModelAt& model_at, const AutonomousOrbit& orbit,
                                             const ContinuationOptions& options) {
  static_assert(AutonomousModel<Model>, "an orbit of unknown period needs an autonomous model (model.hpp)");
  const int K = orbit.grid.K;
  if (orbit.sequence.size() != static_cast<long>(Model::d) * K || !(orbit.period > 0))
    throw BadInput("continue_autonomous_orbit: needs a solved orbit (" + std::to_string(orbit.sequence.size()) +
                   " states for K = " + std::to_string(K) + ", period " + format_number(orbit.period) + ")");
  Eigen::VectorXd start(orbit.sequence.size() + 1);
  start << orbit.sequence, orbit.period;
  const ContinuationOptions o = continuation_detail::checked_options(options);
  const continuation_detail::AutonomousBranch<Model, ModelAt> branch(model_at, K, o);
  return continuation_detail::trace_branch(branch, start, o, nullptr, o.from);
}

}  // namespace delayspec
