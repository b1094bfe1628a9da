#include "delayspec/resolution_study.hpp"

#include <algorithm>

#include "delayspec/error_expansion.hpp"
#include "delayspec/errors.hpp"

namespace delayspec {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

LevelResult level_result(const FloquetResult& result, long n, long K) {
  LevelResult r;
  r.multipliers = result.multipliers;
  r.operator_applications = result.operator_applications;
  const double radius = result.multipliers.empty() ? 0.0 : std::abs(result.multipliers.front());
  for (size_t k = 0; k < result.multipliers.size(); ++k)
    r.accuracy.push_back(multiplier_accuracy(result.multipliers[k],
                                             k < result.residuals.size() ? result.residuals[k] : NAN, n, K, radius));
  return r;
}

ResolutionStudy::ResolutionStudy(std::shared_ptr<const ModelAnalyses> analyses, MapSettings map,
                                 OrbitSettings orbit, FloquetOptions solver, std::function<void()> on_level)
    : analyses_(std::move(analyses)),
      map_(map),
      orbit_(std::move(orbit)),
      solver_(std::move(solver)),
      on_level_(std::move(on_level)) {}

MapSettings ResolutionStudy::map_at(int N) const {
  MapSettings at = map_;
  at.N = N;
  return at;
}

bool ResolutionStudy::grid_fits(int N) const {
  try {
    analyses_->grid(map_at(N));
    return true;
  } catch (const BadInput&) {
    return false;
  }
}

long ResolutionStudy::dimension(int N) const {
  return analyses_->grid(map_at(N)).dimension(analyses_->state_dimension());
}

RichardsonOptions ResolutionStudy::expansion() const { return error_expansion(*analyses_, map_.step); }

std::optional<LevelResult> ResolutionStudy::retry(int N, int count, int from_N) {
  if (!orbit_failed_.count(N) || !sequences_.count(from_N)) return std::nullopt;
  return run(N, count, &sequences_.at(from_N), from_N);
}

LevelResult ResolutionStudy::run(int N, int count, const Eigen::VectorXd* guess, int from_N) {
  LevelResult r;
  const auto start = std::chrono::steady_clock::now();
  bool orbit_found = false;
  const MapSettings map = map_at(N);
  try {
    OrbitRequest request;
    request.newton_guess = guess;
    request.sequence = true;
    LinearisedOrbit at_orbit = analyses_->linearised_orbit(map, orbit_, request);
    orbit_found = true;
    const LinearOperator& op = *at_orbit.monodromy;
    FloquetOptions fo = solver_;
    fo.nev = static_cast<int>(std::min<long>(count, op.rows()));
    r = level_result(floquet_multipliers(op, fo), op.rows(), analyses_->grid(map).K);
    if (at_orbit.sequence.size() > 0) sequences_[N] = std::move(at_orbit.sequence);
    if (guess) r.note = "orbit by Newton from the orbit of N = " + std::to_string(from_N) + ", after: " + failed_.at(N);
  } catch (const NumericalFailure& e) {
    r = {};
    r.failure = e.what();
    if (!orbit_found) orbit_failed_.insert(N);
    failed_[N] = r.failure;
  }
  r.seconds = seconds_since(start);
  if (on_level_) on_level_();
  return r;
}

ErrorBars ResolutionStudy::error_bars(const LevelResult& at_N, Eigen::VectorXd orbit_at_N, double& seconds) {
  const auto start = std::chrono::steady_clock::now();
  constexpr int kExtra = 2;  // candidates beyond nev for the matching (convergence.hpp)
  const int N = map_.N;
  FloquetOptions coarse = solver_;
  coarse.ncv = 0;  // the automatic subspace: a user's ncv may exceed a coarse level's dimension
  coarse.nev = solver_.nev + kExtra;
  // A valid grid on which the solver's options hold, with more than the candidates (a proper
  // sub-spectrum).
  auto valid = [&](int level_N) {
    if (!grid_fits(level_N)) return false;
    const long n = dimension(level_N);
    FloquetOptions checked = coarse;
    checked.nev = static_cast<int>(std::min<long>(coarse.nev, n));
    try {
      validate_floquet_options(checked, n);
    } catch (const BadInput&) {
      return false;
    }
    return n > coarse.nev;
  };
  std::vector<int> Ns = coarser_levels(N, valid);
  ResolutionStudy levels(analyses_, map_, orbit_, coarse);
  std::vector<LevelResult> results;
  for (int level_N : Ns) results.push_back(levels.level(level_N, coarse.nev));
  if (orbit_at_N.size() > 0) {
    levels.keep_orbit(N, std::move(orbit_at_N));
    for (size_t i = 0; i < Ns.size(); ++i)
      if (!results[i].failure.empty())
        if (std::optional<LevelResult> again = levels.retry(Ns[i], coarse.nev, N)) {
          const std::string first = results[i].failure;
          results[i] = std::move(*again);
          if (!results[i].failure.empty()) results[i].failure = first + "; retried: " + results[i].failure;
        }
  }
  Ns.push_back(N);
  results.push_back(at_N);
  seconds = seconds_since(start);
  ErrorBars bars = delayspec::error_bars(Ns, results, expansion());
  // A coarse level that cannot be had is said, not dropped silently (issue 61 item 9).
  if (Ns.size() < 3)
    bars.note += (bars.note.empty() ? "" : "; ") + std::to_string(Ns.size() - 1) +
                 " coarse level(s) of the two wanted: below N = " + std::to_string(N) +
                 ", a level needs a grid the delays fit and more than nev + 2 = " + std::to_string(coarse.nev) +
                 " multipliers (its dimension d (N + 1))";
  return bars;
}

FloquetAtResolution ResolutionStudy::floquet(bool with_error_bars, bool retry_from_N, bool keep_sequence) {
  FloquetAtResolution out;
  const auto start = std::chrono::steady_clock::now();
  OrbitRequest request;
  request.sequence = (with_error_bars && retry_from_N) || keep_sequence;  // where a coarser level's Newton may start
  out.at_orbit = analyses_->linearised_orbit(map_, orbit_, request);
  out.orbit_seconds = seconds_since(start);
  out.result = floquet_multipliers(*out.at_orbit.monodromy, solver_);
  out.at_orbit.monodromy.reset();  // its step maps: memory the coarser levels can use
  // Each multiplier's accuracy (multiplier_accuracy): the ones below it are not printed as values.
  out.at_N = level_result(out.result, dimension(map_.N), analyses_->grid(map_).K);
  if (with_error_bars) {
    Eigen::VectorXd from;  // the orbit at N, where a coarse level whose orbit failed is retried from
    if (retry_from_N) from = keep_sequence ? out.at_orbit.sequence : std::move(out.at_orbit.sequence);
    out.bars = error_bars(out.at_N, std::move(from), out.error_bar_seconds);
  }
  return out;
}

// --- An autonomous orbit of unknown period ------------------------------------------------------

AutonomousOrbitOptions autonomous_orbit_options(const OrbitSettings& orbit, const StepOptions& step, int N,
                                                double period_guess) {
  AutonomousOrbitOptions o;
  o.period_guess = period_guess;
  o.N = N;
  o.guess_periods = static_cast<int>(orbit.guess_periods);
  o.newton = orbit.newton;
  o.step = step;
  o.coarse_N = orbit.coarse_N;
  // newton: sparse LU on the whole period; auto and shooting: nested shooting (sparse LU alone
  // below refinement coarse_N, where it has one level)
  if (orbit.method == OrbitMethod::simulate)
    throw BadInput("`orbit = simulate` with `period_guess`: an orbit of unknown period is solved for with its "
                   "period (orbit = newton, shooting or auto)");
  o.method = orbit.method == OrbitMethod::newton ? AutonomousOrbitMethod::newton : AutonomousOrbitMethod::shooting;
  return o;
}

AutonomousFloquetLevel autonomous_level(const ModelAnalyses& analyses, const StepOptions& step, int N,
                                        double period_guess, const OrbitSettings& orbit,
                                        const FloquetOptions& solver) {
  AutonomousLinearisedOrbit at = analyses.autonomous_orbit(autonomous_orbit_options(orbit, step, N, period_guess));
  AutonomousFloquetLevel level;
  level.N = N;
  level.orbit = std::move(at.orbit);
  FloquetOptions fo = solver;
  fo.nev = static_cast<int>(std::min<long>(solver.nev + 1, at.monodromy->rows()));
  level.result = floquet_multipliers(*at.monodromy, fo);
  const LevelResult all = level_result(level.result, at.monodromy->rows(), level.orbit.grid.K);
  const size_t trivial = trivial_multiplier_index(all.multipliers);
  level.trivial = all.multipliers.at(trivial);
  for (size_t i = 0; i < all.multipliers.size(); ++i)
    if (i != trivial) {
      level.others.multipliers.push_back(all.multipliers[i]);
      level.others.accuracy.push_back(all.accuracy[i]);
    }
  return level;
}

void PeriodStudy::add(int N, const AutonomousOrbit& orbit) {
  Ns.push_back(N);
  Ks.push_back(orbit.grid.K);
  periods.push_back(orbit.period);
}

void PeriodStudy::extrapolate(const RichardsonOptions& expansion) {
  if (periods.size() < 2) return;
  std::vector<double> h;
  std::vector<std::complex<double>> values;
  for (size_t i = 0; i < periods.size(); ++i) {
    h.push_back(1.0 / Ks[i]);
    values.emplace_back(periods[i]);
  }
  extrapolated = richardson_extrapolate(h, values, expansion);
}

AutonomousFloquet autonomous_floquet(const ModelAnalyses& analyses, const StepOptions& step, int N,
                                     double period_guess, const OrbitSettings& orbit, const FloquetOptions& solver,
                                     bool with_error_bars) {
  AutonomousFloquet out;
  out.at_N = autonomous_level(analyses, step, N, period_guess, orbit, solver);
  if (!with_error_bars) return out;
  const auto start = std::chrono::steady_clock::now();
  // The coarser levels, each from the period found at N (the guess closest to their orbit).
  // (quartering: error_bars.hpp says why an autonomous orbit's levels are not halved yet)
  std::vector<int> Ns = coarser_levels(N, [](int level_N) { return level_N >= 8; }, 4, LevelSpacing::quartering);
  std::vector<LevelResult> levels;
  for (int level_N : Ns) {
    LevelResult r;
    try {
      AutonomousFloquetLevel level = autonomous_level(analyses, step, level_N, out.at_N.orbit.period, orbit, solver);
      out.period.add(level_N, level.orbit);
      r = std::move(level.others);
    } catch (const NumericalFailure& e) {
      r.failure = e.what();
    }
    levels.push_back(std::move(r));
  }
  Ns.push_back(N);
  levels.push_back(out.at_N.others);
  out.period.add(N, out.at_N.orbit);
  const RichardsonOptions expansion = error_expansion(analyses, step);
  out.bars = error_bars(Ns, levels, expansion);
  out.period.extrapolate(expansion);
  out.error_bar_seconds = seconds_since(start);
  return out;
}

}  // namespace delayspec
