#pragma once
// Shared by the commands that solve at several resolutions (converge, bench, floquet's error
// bars, chart): the key lists they read (Ns / N_min..N_max, continue_Ns, ...), the exact
// references, the problem at another resolution N with its orbit and monodromy (bench), and the
// problem's resolution study (the engine's, delayspec/resolution_study.hpp).
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "scene/keys/config.hpp"
#include "delayspec/convergence.hpp"
#include "delayspec/error_bars.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/periodic_orbit.hpp"
#include "delayspec/resolution_study.hpp"
#include "scene/problem/orbit_settings.hpp"
#include "scene/problem/problem.hpp"
#include "scene/output/progress.hpp"

namespace delayspec::cli {

// With `Ns` the levels are the list's and the scene's N is not one of them: the problem is built
// at the list's first N, so that an N no level uses is not checked against the grid (tau/T =
// 19/13 needs N divisible by 19: a scene's N = 100 refused `converge` with valid Ns, issue 61
// item 6). Call before read_problem.
void use_first_level_as_N(Config& config);

// `Ns` (comma list), or `N_min` .. `N_max` doubling (N_min, 2 N_min, ... <= N_max); defaults
// when neither is given (moved up to the first valid N when the grid needs multiples: 26, 52, ...
// for tau/T = 2). Validated: each N >= 1, strictly increasing, and a valid grid for the
// problem (make_grid names N when the delay/period ratio needs a multiple).
std::vector<int> read_N_list(Config& config, const Problem& problem, int default_min, int default_max);

// The key `reference` (exact, extrapolated, finest, auto): what converge and bench score against.
ReferenceKind read_reference_kind(Config& config);

// An increasing list of levels N for error bars (continue_Ns, boundary_Ns): each N in 1 .. 1e7,
// strictly increasing (BadInput naming the key); empty when the key is not given.
std::vector<int> read_levels(Config& config, const std::string& key);

// A comma-separated list of words, each one of `allowed` (BadInput naming the key and the word).
std::vector<std::string> read_word_list(Config& config, const std::string& key, const std::string& fallback,
                                        const std::vector<std::string>& allowed);

// Reference multipliers that no step map produced, when the model has them: `source` "lambert_w"
// (the built-in linear model: exact) or "spectral" (a linear model with one delay tau = T:
// piecewise Chebyshev collocation at degree 32 and 40 on each half of every interval between
// switches, spectral_reference.hpp, taken where its estimate is within 1e-10 of every multiplier
// asked for), `precision` their relative accuracy; empty multipliers: none.
struct ExactReference {
  std::vector<std::complex<double>> multipliers;
  double precision = 1e-14;
  std::string source;
};
ExactReference exact_reference(const Problem& problem, int count);

// Builds the problem at resolution N with the given events mode, finds its periodic orbit (as
// `request` says: from another level's orbit by Newton, and whether to keep the sequence) and
// calls fn(monodromy, linearised_orbit, setup_seconds).
template <class Fn>
void with_monodromy(const Problem& problem, EventMode events, const OrbitSettings& orbit_settings, int N, Fn&& fn,
                    const OrbitRequest& request = {}) {
  const auto start = std::chrono::steady_clock::now();
  Problem p = problem;
  p.events = events;
  p.N = N;
  const LinearisedOrbit at_orbit = p.analyses->linearised_orbit(p.map_settings(), orbit_settings, request);
  const double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fn(static_cast<const LinearOperator&>(*at_orbit.monodromy), at_orbit, setup);
}

// The Richardson expansion of the problem's discretisation error (delayspec/error_expansion.hpp,
// the rule's one home).
RichardsonOptions error_expansion(const Problem& problem);

// The problem's resolution study (delayspec/resolution_study.hpp): its model and steps, its N the
// study's resolution of record. on_level: after every level (a progress counter).
ResolutionStudy resolution_study(const Problem& problem, const OrbitSettings& orbit, const FloquetOptions& solver,
                                 Progress* progress = nullptr);

}  // namespace delayspec::cli
