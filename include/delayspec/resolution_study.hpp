#pragma once
// ResolutionStudy: one model's periodic orbit and Floquet multipliers solved at several
// resolutions N, the loop behind every number delayspec extrapolates in N (issue 57 item 2):
// floquet's error bars (error_bars.hpp), converge's levels (convergence.hpp), chart's verdicts,
// and the same for an autonomous orbit of unknown period with its period.
//
// A level is one solve: the orbit at N (as OrbitSettings says), the map's monodromy there, the
// leading multipliers with their accuracy (multiplier_accuracy, convergence.hpp). The orbits of
// the levels that succeeded are kept (the states of one map: a few MB at most), so that a level
// whose orbit failed is retried once by Newton from another level's orbit, prolonged to its N
// (only a failed orbit is worth a second try; a failed eigen-solve stands). The error expansion
// is the model's (error_expansion.hpp, the rule's one home): a new scheme changes its orders
// there, and every study here follows.
//
// The study knows no key and no file: the scene layer reads its settings and writes its results.
#include <chrono>
#include <complex>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "delayspec/autonomous_orbit.hpp"
#include "delayspec/convergence.hpp"
#include "delayspec/error_bars.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/model_analyses.hpp"
#include "delayspec/richardson.hpp"

namespace delayspec {

// A level's multipliers with their accuracy (multiplier_accuracy) from one solve of a monodromy of
// dimension n that is a product of K step maps.
LevelResult level_result(const FloquetResult& result, long n, long K);

// floquet at one resolution: the orbit at map.N and its monodromy's leading multipliers, with the
// error bars of two coarser levels when asked for.
struct FloquetAtResolution {
  LinearisedOrbit at_orbit;             // the orbit, its contacts and grid (the monodromy is released)
  FloquetResult result;                 // the solve at N
  LevelResult at_N;                     // its multipliers with their accuracy
  std::optional<ErrorBars> bars;        // with error bars
  double orbit_seconds = 0;             // finding the orbit and its linearisation (the step maps)
  double error_bar_seconds = 0;         // the coarser levels
};

class ResolutionStudy {
 public:
  // The model `analyses` with the steps of `map`, whose N is the study's resolution of record (the
  // solve floquet's error bars belong to); every level is the same map at its own N. on_level, when
  // set, is called after every level (a progress counter).
  ResolutionStudy(std::shared_ptr<const ModelAnalyses> analyses, MapSettings map, OrbitSettings orbit,
                  FloquetOptions solver, std::function<void()> on_level = {});

  const MapSettings& map() const { return map_; }
  MapSettings map_at(int N) const;
  // Whether the grid can be made at N (a delay/period ratio may need multiples of a step count).
  bool grid_fits(int N) const;
  // d (M + 1) at N: the dimension of the history vector and the monodromy.
  long dimension(int N) const;
  // The powers of h of the discretisation error (error_expansion.hpp).
  RichardsonOptions expansion() const;

  // The leading `count` multipliers at N (failure in the result, not thrown, when the orbit or the
  // eigen-solve fails numerically).
  LevelResult level(int N, int count) { return run(N, count, nullptr); }
  // A level whose orbit failed, once more by Newton from the orbit of from_N; nullopt when the
  // level's orbit did not fail or from_N has no orbit.
  std::optional<LevelResult> retry(int N, int count, int from_N);
  // A level computed elsewhere (the solve at N itself): its orbit, for the retries of the others.
  void keep_orbit(int N, Eigen::VectorXd sequence) { sequences_[N] = std::move(sequence); }

  // floquet's error bars (error_bars.hpp) for `at_N`, the multipliers of the solve at map().N: the
  // coarser levels (coarser_levels: N/4 and N/2, valid grids on which the solver's options hold
  // with more than nev + 2 multipliers), each solved with nev + 2 candidates and ncv automatic; a
  // level whose orbit failed is retried from `orbit_at_N` (the orbit's states at N) when given.
  // `seconds` receives what the coarser levels cost.
  ErrorBars error_bars(const LevelResult& at_N, Eigen::VectorXd orbit_at_N, double& seconds);

  // The solve at map().N with the solver's options, and with_error_bars its bars (above, with the
  // retries from the orbit at N when retry_from_N); keep_sequence: the orbit's states of one map
  // stay in at_orbit.sequence (nonlinear models). NumericalFailure when the orbit or the solve at
  // N fails.
  FloquetAtResolution floquet(bool with_error_bars, bool retry_from_N = true, bool keep_sequence = false);

 private:
  LevelResult run(int N, int count, const Eigen::VectorXd* guess, int from_N = 0);

  std::shared_ptr<const ModelAnalyses> analyses_;
  MapSettings map_;
  OrbitSettings orbit_;
  FloquetOptions solver_;
  std::function<void()> on_level_;
  std::map<int, Eigen::VectorXd> sequences_;  // N -> orbit states of one map, levels that succeeded
  std::set<int> orbit_failed_;                // N whose orbit (not the eigen-solve) failed
  std::map<int, std::string> failed_;         // N -> why it failed
};

// --- An autonomous orbit of unknown period (autonomous_orbit.hpp) -------------------------------

// How the orbit at N is found from period_guess with `orbit`'s method: newton, sparse LU on the
// whole period; auto and shooting, nested shooting (autonomous_shooting.hpp). BadInput for
// orbit = simulate (an orbit of unknown period is solved for with its period).
AutonomousOrbitOptions autonomous_orbit_options(const OrbitSettings& orbit, const StepOptions& step, int N,
                                                double period_guess);

struct AutonomousFloquetLevel {
  int N = 0;
  AutonomousOrbit orbit;
  FloquetResult result;          // every multiplier computed (nev + 1)
  std::complex<double> trivial;  // the one nearest 1 (the time shift's)
  LevelResult others;            // the rest, by modulus, with their accuracy
};

// One level: the orbit at N from period_guess (its guess simulated for orbit.guess_periods periods)
// and nev + 1 multipliers, split into the trivial one and the others. BadInput: period_guess <= 0,
// a forced or linear model, orbit = simulate; NumericalFailure: no orbit.
AutonomousFloquetLevel autonomous_level(const ModelAnalyses& analyses, const StepOptions& step, int N,
                                        double period_guess, const OrbitSettings& orbit,
                                        const FloquetOptions& solver);

// The period at several levels and its Richardson extrapolation in h = 1 / K (the step in the
// scaled time), with the model's error expansion.
struct PeriodStudy {
  std::vector<int> Ns;          // the levels whose orbit was found, increasing
  std::vector<int> Ks;          // their steps per period
  std::vector<double> periods;  // their periods
  std::optional<Extrapolation> extrapolated;  // two levels or more
  void add(int N, const AutonomousOrbit& orbit);
  void extrapolate(const RichardsonOptions& expansion);
};

struct AutonomousFloquet {
  AutonomousFloquetLevel at_N;
  std::optional<ErrorBars> bars;  // of at_N.others (with error bars)
  PeriodStudy period;             // with error bars: the coarser levels and N
  double error_bar_seconds = 0;
};

// The orbit at N from period_guess (as autonomous_level finds it), its top nev multipliers besides
// the trivial one; with error bars the coarser levels (coarser_levels, quartering: error_bars.hpp
// says why; their orbits from the period found at N). BadInput: period_guess <= 0, a forced or
// linear model; NumericalFailure: no orbit at N.
AutonomousFloquet autonomous_floquet(const ModelAnalyses& analyses, const StepOptions& step, int N,
                                     double period_guess, const OrbitSettings& orbit, const FloquetOptions& solver,
                                     bool with_error_bars);

}  // namespace delayspec
