#include "scene/problem/autonomous_floquet.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "delayspec/errors.hpp"
#include "scene/output/output.hpp"
#include "scene/problem/level_runner.hpp"

namespace delayspec::cli {

std::optional<double> read_period_guess(Config& config, const Problem& problem) {
  if (config.get_string("period_guess", "none") == "none") return std::nullopt;
  const double guess = config.get_double("period_guess", 0);
  if (!problem.analyses->is_autonomous())
    throw BadInput("`period_guess` with `model = " + problem.model_name +
                   "`: a forced model's orbit has the forcing's period; `period_guess` is for autonomous models");
  return guess;
}

AutonomousOrbitOptions autonomous_orbit_options(const Problem& problem, int N, double period_guess,
                                                const OrbitSettings& orbit) {
  AutonomousOrbitOptions o;
  o.period_guess = period_guess;
  o.N = N;
  o.guess_periods = static_cast<int>(orbit.guess_periods);
  o.newton = orbit.newton;
  o.step = step_options(problem);
  o.coarse_N = orbit.coarse_N;
  // newton: sparse LU on the whole period; auto and shooting: nested shooting (sparse LU alone
  // below refinement coarse_N, where it has one level)
  if (orbit.method == OrbitMethod::simulate)
    throw BadInput("`orbit = simulate` with `period_guess`: an orbit of unknown period is solved for with its "
                   "period (orbit = newton, shooting or auto)");
  o.method = orbit.method == OrbitMethod::newton ? AutonomousOrbitMethod::newton : AutonomousOrbitMethod::shooting;
  return o;
}

AutonomousFloquetLevel autonomous_level(const Problem& problem, int N, double period_guess,
                                        const OrbitSettings& orbit, const FloquetOptions& solver) {
  AutonomousLinearisedOrbit at = problem.analyses->autonomous_orbit(autonomous_orbit_options(problem, N, period_guess, orbit));
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

nlohmann::json period_study_json(const PeriodStudy& study) {
  nlohmann::json p;
  p["Ns"] = study.Ns;
  p["steps_per_period"] = study.Ks;
  p["periods"] = study.periods;
  if (study.extrapolated) {
    p["extrapolated"] = study.extrapolated->value.real();
    p["error_estimate"] = number_or_null(study.extrapolated->error_estimate);
    p["note"] = study.extrapolated->note;
  }
  return p;
}

AutonomousFloquet autonomous_floquet(const Problem& problem, double period_guess, const OrbitSettings& orbit,
                                     const FloquetOptions& solver, bool with_error_bars) {
  AutonomousFloquet out;
  out.at_N = autonomous_level(problem, problem.N, period_guess, orbit, solver);
  if (!with_error_bars) return out;
  const auto start = std::chrono::steady_clock::now();
  // The coarser levels, each from the period found at N (the guess closest to their orbit).
  // (quartering: error_bars.hpp says why an autonomous orbit's levels are not halved yet)
  std::vector<int> Ns = coarser_levels(problem.N, [](int N) { return N >= 8; }, 4, LevelSpacing::quartering);
  std::vector<LevelResult> levels;
  for (int N : Ns) {
    LevelResult r;
    try {
      AutonomousFloquetLevel level =
          autonomous_level(problem, N, out.at_N.orbit.period, orbit, solver);
      out.period.add(N, level.orbit);
      r = std::move(level.others);
    } catch (const NumericalFailure& e) {
      r.failure = e.what();
    }
    levels.push_back(std::move(r));
  }
  Ns.push_back(problem.N);
  levels.push_back(out.at_N.others);
  out.period.add(problem.N, out.at_N.orbit);
  out.bars = error_bars(Ns, levels, error_expansion(problem));
  out.period.extrapolate(error_expansion(problem));
  out.error_bar_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

void add_autonomous_floquet_json(nlohmann::json& j, const AutonomousFloquet& r, double period_guess) {
  const AutonomousOrbit& orbit = r.at_N.orbit;
  j["period"] = orbit.period;
  j["period_guess"] = period_guess;
  j["steps_per_period"] = orbit.grid.K;
  j["trivial_multiplier"] = {{"re", r.at_N.trivial.real()},
                             {"im", r.at_N.trivial.imag()},
                             {"distance_from_1", std::abs(r.at_N.trivial - 1.0)}};
  j["multipliers"] = multipliers_json(r.at_N.others.multipliers);
  add_resolution_json(j["multipliers"], r.at_N.others.multipliers, r.at_N.others.accuracy);
  if (r.bars) {
    add_error_bars_json(j["multipliers"], *r.bars);
    j["verdict"] = to_string(r.bars->verdict);
    j["error_bars"] = error_bars_json(*r.bars, r.error_bar_seconds);
    j["period_error_bars"] = period_study_json(r.period);
  }
  j["orbit"] = {{"method", orbit.method == AutonomousOrbitMethod::newton
                                ? "newton (period unknown, integral phase condition)"
                                : "shooting (nested, period unknown, phase condition on the history)"},
                {"newton_iterations", orbit.newton_iterations},
                {"newton_residuals", orbit.newton_residuals},
                {"periods", orbit.periods},
                {"residual", orbit.residual}};
}

void print_autonomous_floquet(std::ostream& out, const AutonomousFloquet& r, double period_guess) {
  const AutonomousOrbit& orbit = r.at_N.orbit;
  char line[256];
  std::snprintf(line, sizeof line,
                "orbit of unknown period: T = %.15g from period_guess %g (%s, %d Newton iterations, |F|_inf = %.1e), "
                "%d steps per period\n",
                orbit.period, period_guess, to_string(orbit.method).c_str(), orbit.newton_iterations, orbit.residual,
                orbit.grid.K);
  out << line;
  if (const auto& x = r.period.extrapolated) {
    std::snprintf(line, sizeof line, "period: %.12g +- %.1e at N (from N = ", orbit.period,
                  std::abs(orbit.period - x->value.real()) + x->error_estimate);
    out << line;
    for (size_t i = 0; i < r.period.Ns.size(); ++i) out << (i ? ", " : "") << r.period.Ns[i];
    std::snprintf(line, sizeof line, "); extrapolated %.12g +- %.1e\n", x->value.real(), x->error_estimate);
    out << line;
  }
  std::snprintf(line, sizeof line,
                "trivial multiplier (the time shift's): %+.15f %+.1ei, |mu - 1| = %.1e (1 for the exact orbit)\n",
                r.at_N.trivial.real(), r.at_N.trivial.imag(), std::abs(r.at_N.trivial - 1.0));
  out << line;
  out << "leading " << r.at_N.others.multipliers.size() << " other Floquet multipliers ("
      << to_string(r.at_N.result.solver) << "):\n";
  print_multipliers(out, r.at_N.others.multipliers, r.at_N.others.accuracy);
  if (r.bars) print_error_bars(out, r.at_N.others.multipliers, *r.bars);
}

}  // namespace delayspec::cli
