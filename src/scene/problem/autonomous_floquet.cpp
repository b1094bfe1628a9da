#include "scene/problem/autonomous_floquet.hpp"

#include <algorithm>
#include <cstdio>

#include "delayspec/errors.hpp"
#include "scene/output/output.hpp"

namespace delayspec::cli {

std::optional<double> read_period_guess(Config& config, const Problem& problem) {
  if (config.get_string("period_guess", "none") == "none") return std::nullopt;
  const double guess = config.get_double("period_guess", 0);
  if (!problem.analyses->is_autonomous())
    throw BadInput("`period_guess` with `model = " + problem.model_name +
                   "`: a forced model's orbit has the forcing's period; `period_guess` is for autonomous models");
  return guess;
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
