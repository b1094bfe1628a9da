#pragma once
// `floquet` for a periodic orbit of unknown period (period_guess; autonomous_orbit.hpp): the
// orbit, its period, its trivial multiplier (the time shift's, 1 for the exact orbit) apart from
// the others, and with error bars the same at two coarser levels: the other multipliers' bars and
// verdict as for any orbit (error_bars.hpp), the period extrapolated by Richardson in h = 1 / K.
#include <complex>
#include <ostream>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "delayspec/autonomous_orbit.hpp"
#include "delayspec/error_bars.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/richardson.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

struct AutonomousFloquetLevel {
  int N = 0;
  AutonomousOrbit orbit;
  FloquetResult result;               // every multiplier computed (nev + 1)
  std::complex<double> trivial;       // the one nearest 1
  LevelResult others;                 // the rest, by modulus, with their accuracy
};

struct AutonomousFloquet {
  AutonomousFloquetLevel at_N;
  std::optional<ErrorBars> bars;  // of at_N.others (error_bars = on)
  std::vector<int> Ns;            // the levels whose orbit was found, coarsest first; the last is N
  std::vector<int> Ks;            // their steps per period
  std::vector<double> periods;    // their periods
  std::optional<Extrapolation> period;  // Richardson on the periods (two levels or more)
  double error_bar_seconds = 0;
};

// The orbit at problem.N from period_guess (its guess simulated for guess_periods periods), its
// top nev multipliers besides the trivial one; with error_bars the coarser levels (coarser_levels;
// their orbits from the period found at N). BadInput: period_guess <= 0, a forced or linear model;
// NumericalFailure: no orbit at N.
AutonomousFloquet autonomous_floquet(const Problem& problem, double period_guess, int guess_periods,
                                     const OrbitByNewtonOptions& newton, const FloquetOptions& solver,
                                     bool with_error_bars);

// The JSON fields `floquet --json` adds or replaces for such an orbit (docs/cli.md, floquet):
// period, period_guess, steps_per_period, trivial_multiplier, multipliers (the others), verdict,
// error_bars, period_error_bars, orbit.
void add_autonomous_floquet_json(nlohmann::json& j, const AutonomousFloquet& r, double period_guess);
// The text report's lines after the header.
void print_autonomous_floquet(std::ostream& out, const AutonomousFloquet& r, double period_guess);

}  // namespace delayspec::cli
