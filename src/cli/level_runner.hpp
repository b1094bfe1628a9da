#pragma once
// Shared by the study commands (converge, bench): the problem at another resolution N, its
// periodic orbit and monodromy, and the key lists they read (Ns / N_min..N_max).
#include <chrono>
#include <string>
#include <vector>

#include "config.hpp"
#include "delayspec/periodic_orbit.hpp"
#include "orbit_settings.hpp"
#include "problem.hpp"

namespace delayspec::cli {

// `Ns` (comma list), or `N_min` .. `N_max` doubling (N_min, 2 N_min, ... <= N_max); defaults
// when neither is given. Validated: each N >= 1, strictly increasing, and a valid grid for the
// problem (make_grid names N when the delay/period ratio needs a multiple).
std::vector<int> read_N_list(Config& config, const Problem& problem, int default_min, int default_max);

// A comma-separated list of words, each one of `allowed` (BadInput naming the key and the word).
std::vector<std::string> read_word_list(Config& config, const std::string& key, const std::string& fallback,
                                        const std::vector<std::string>& allowed);

// The exact leading multipliers when the model has them (linear: Lambert W), else empty.
std::vector<std::complex<double>> exact_multipliers(const Problem& problem, int count);

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

}  // namespace delayspec::cli
