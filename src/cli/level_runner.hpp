#pragma once
// Shared by the study commands (converge, bench): the problem at another resolution N, its
// periodic orbit and monodromy, and the key lists they read (Ns / N_min..N_max).
#include <chrono>
#include <string>
#include <vector>

#include "config.hpp"
#include "delayspec/periodic_orbit.hpp"
#include "delayspec/stroboscopic_map.hpp"
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

// How with_monodromy finds the orbit, beyond the orbit settings.
struct LevelOrbit {
  // in: when set, Newton (orbit_by_newton) from this sequence (another level's orbit, any K:
  // prolonged) instead of the configured method.
  const Eigen::VectorXd* newton_guess = nullptr;
  // out: when set, the orbit's states over one map (nonlinear models; left empty for linear ones).
  Eigen::VectorXd* sequence = nullptr;
};

// Builds the problem at resolution N with the given events mode, finds its periodic orbit and
// calls fn(monodromy, orbit, setup_seconds). fn is generic in the Monodromy<D> type.
template <class Fn>
void with_monodromy(const Problem& problem, EventMode events, const OrbitSettings& orbit_settings, int N, Fn&& fn,
                    const LevelOrbit& level_orbit = {}) {
  const auto start = std::chrono::steady_clock::now();
  Problem p = problem;
  p.events = events;
  p.N = N;
  with_map(p, [&](const auto& model, const auto& map) {
    using Model = std::decay_t<decltype(model)>;
    const long K = map.grid().K;
    PeriodicOrbit orbit;
    OrbitLinearisation<Model::d> at_orbit;  // step maps and states of one map at the orbit
    if constexpr (!Model::is_linear) {
      if (level_orbit.newton_guess) {
        const Eigen::VectorXd guess = prolong_periodic_sequence(*level_orbit.newton_guess, Model::d, K);
        orbit = orbit_by_newton(map, guess, orbit_settings.newton);
        map.apply(orbit.history, &at_orbit.maps, &at_orbit.states);
      } else {
        orbit = find_orbit(model, map, orbit_settings, &at_orbit);
      }
      if (level_orbit.sequence) {  // the states u_0 .. u_{K-1}
        Eigen::VectorXd& x = *level_orbit.sequence;
        x.resize(static_cast<long>(Model::d) * K);
        for (long l = 0; l < K; ++l) x.template segment<Model::d>(Model::d * l) = at_orbit.states[l];
      }
    } else {
      orbit = find_orbit(model, map, orbit_settings, &at_orbit);
    }
    const Monodromy<Model::d> monodromy(map.grid(), std::move(at_orbit.maps));
    const double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    fn(monodromy, orbit, setup);
  });
}

}  // namespace delayspec::cli
