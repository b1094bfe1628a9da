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

// The period at several levels and its Richardson extrapolation in h = 1 / K (the step in the
// scaled time), with the problem's error expansion.
struct PeriodStudy {
  std::vector<int> Ns;          // the levels whose orbit was found, increasing
  std::vector<int> Ks;          // their steps per period
  std::vector<double> periods;  // their periods
  std::optional<Extrapolation> extrapolated;  // two levels or more
  void add(int N, const AutonomousOrbit& orbit);
  void extrapolate(const RichardsonOptions& expansion);
};
// {Ns, steps_per_period, periods, extrapolated, error_estimate, observed_order, note}
nlohmann::json period_study_json(const PeriodStudy& study);

struct AutonomousFloquet {
  AutonomousFloquetLevel at_N;
  std::optional<ErrorBars> bars;  // of at_N.others (error_bars = on)
  PeriodStudy period;             // error_bars = on: the coarser levels and N
  double error_bar_seconds = 0;
};

// The key `period_guess` (absent: "none", the forced orbit as ever); BadInput when it is not a
// number, or given for a model that is not autonomous (its orbit has the forcing's period).
std::optional<double> read_period_guess(Config& config, const Problem& problem);

// How the orbit at N is found from period_guess (below). BadInput: orbit = simulate.
AutonomousOrbitOptions autonomous_orbit_options(const Problem& problem, int N, double period_guess,
                                                const OrbitSettings& orbit);

// One level: the orbit at N from period_guess (its guess simulated for orbit.guess_periods
// periods; orbit = newton: sparse LU on the whole period, auto or shooting: nested shooting,
// autonomous_shooting.hpp) and nev + 1 multipliers, split into the trivial one and the others.
// BadInput: period_guess <= 0, a forced or linear model, orbit = simulate; NumericalFailure: no orbit.
AutonomousFloquetLevel autonomous_level(const Problem& problem, int N, double period_guess,
                                        const OrbitSettings& orbit, const FloquetOptions& solver);

// The orbit at problem.N from period_guess (as autonomous_level finds it), its
// top nev multipliers besides the trivial one; with error_bars the coarser levels (coarser_levels;
// their orbits from the period found at N). BadInput: period_guess <= 0, a forced or linear model;
// NumericalFailure: no orbit at N.
AutonomousFloquet autonomous_floquet(const Problem& problem, double period_guess, const OrbitSettings& orbit,
                                     const FloquetOptions& solver,
                                     bool with_error_bars);

// The JSON fields `floquet --json` adds or replaces for such an orbit (docs/cli.md, floquet):
// period, period_guess, steps_per_period, trivial_multiplier, multipliers (the others), verdict,
// error_bars, period_error_bars, orbit.
void add_autonomous_floquet_json(nlohmann::json& j, const AutonomousFloquet& r, double period_guess);
// The text report's lines after the header.
void print_autonomous_floquet(std::ostream& out, const AutonomousFloquet& r, double period_guess);

}  // namespace delayspec::cli
