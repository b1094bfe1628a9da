// delayspec floquet: the leading Floquet multipliers of the periodic orbit (CLI contract).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>

#include "scene/commands/commands.hpp"
#include "delayspec/floquet.hpp"
#include "scene/problem/autonomous_floquet.hpp"
#include "scene/problem/floquet_settings.hpp"
#include "scene/problem/level_runner.hpp"
#include "delayspec/stroboscopic_map.hpp"
#include "scene/problem/orbit_settings.hpp"
#include "scene/output/output.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

namespace {

// orbit_series = on: the orbit as a time series over one map (issue 61 item 8), {"t": [...],
// NAME: [...] per state component} from its states u_0 .. u_{K-1} (d each) at the times `t_of(l)`.
template <class Time>
nlohmann::json orbit_series_json(const Problem& problem, const Eigen::VectorXd& sequence, long K, const Time& t_of) {
  const size_t d = problem.state_names.size();
  nlohmann::json j;
  std::vector<double> t(static_cast<size_t>(K));
  for (long l = 0; l < K; ++l) t[static_cast<size_t>(l)] = t_of(l);
  j["t"] = t;
  for (size_t c = 0; c < d; ++c) {
    std::vector<double> y(static_cast<size_t>(K));
    // a linear model's orbit is the zero orbit, which it does not store (LinearisedOrbit::sequence)
    for (long l = 0; l < K; ++l)
      y[static_cast<size_t>(l)] =
          sequence.size() == 0 ? 0.0 : sequence[l * static_cast<long>(d) + static_cast<long>(c)];
    j[problem.state_names[c]] = y;
  }
  return j;
}

// The series of orbit_series_json as a table for people: t and one column per state component.
void print_orbit_series(std::ostream& os, const Problem& problem, const nlohmann::json& series) {
  char cell[64];
  os << "orbit series (" << series["t"].size() << " samples over one map):\n";
  std::snprintf(cell, sizeof cell, "%16s", "t");
  os << cell;
  for (const std::string& name : problem.state_names) {
    std::snprintf(cell, sizeof cell, "  %16s", name.c_str());
    os << cell;
  }
  os << "\n";
  for (size_t l = 0; l < series["t"].size(); ++l) {
    std::snprintf(cell, sizeof cell, "%16.10g", series["t"][l].get<double>());
    os << cell;
    for (const std::string& name : problem.state_names) {
      std::snprintf(cell, sizeof cell, "  %16.10g", series[name][l].get<double>());
      os << cell;
    }
    os << "\n";
  }
}

int floquet_of_unknown_period(const Problem& problem, const OrbitSettings& orbit_settings,
                              const FloquetOptions& options, bool with_error_bars, bool with_series,
                              double period_guess, const Invocation& inv, std::chrono::steady_clock::time_point start) {
  const AutonomousFloquet r = autonomous_floquet(*problem.analyses, step_options(problem), problem.N, period_guess,
                                                 orbit_settings, options, with_error_bars);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json series;  // orbit_series = on: u_l at t = l T / K (the scaled problem's uniform grid)
  if (with_series) {
    const AutonomousOrbit& o = r.at_N.orbit;
    const long K = o.sequence.size() / static_cast<long>(problem.state_names.size());
    series = orbit_series_json(problem, o.sequence, K, [&](long l) { return static_cast<double>(l) * o.period / K; });
  }
  if (inv.json) {
    nlohmann::json json;
    json["model"] = problem.model_name;
    json["state_names"] = problem.state_names;
    json["N"] = problem.N;
    json["dimension"] = r.at_N.orbit.history.size();
    json["solver"] = to_string(r.at_N.result.solver);
    add_autonomous_floquet_json(json, r, period_guess);
    if (with_series) json["orbit_series"] = series;
    json["seconds"] = seconds;
    inv.out << json.dump(2) << "\n";
  } else {
    inv.out << "delayspec floquet: model " << problem.model_label << ", autonomous, N = " << problem.N
            << " steps per the longest delay, n = " << r.at_N.orbit.history.size() << "\n";
    print_autonomous_floquet(inv.out, r, period_guess);
    if (with_series) print_orbit_series(inv.out, problem, series);
    inv.out << "time: " << seconds << " s\n";
  }
  return 0;
}

}  // namespace

int command_floquet(Config& config, const Invocation& inv) {
  const auto start = std::chrono::steady_clock::now();
  Problem problem = read_problem(config, 100);
  const OrbitSettings orbit_settings = read_orbit_settings(config);
  const FloquetOptions options = read_floquet_options(config);
  // The error bars (error_bars.hpp): two coarser solves, about 1.3x the single one.
  const bool with_error_bars = config.get_switch("error_bars", true);
  // The orbit's time series in the JSON (d K numbers: off unless asked for)
  const bool with_series = config.get_switch("orbit_series", false);
  // An autonomous model's orbit of unknown period (autonomous_floquet.hpp)
  const std::optional<double> period_guess = read_period_guess(config, problem);
  config.check_all_used();
  if (period_guess)
    return floquet_of_unknown_period(problem, orbit_settings, options, with_error_bars, with_series, *period_guess, inv,
                                     start);
  const long n = problem.dimension();
  validate_floquet_options(options, n);  // before the orbit: fail fast

  // The solve at N and its error bars (delayspec/resolution_study.hpp): two coarser solves, about
  // 1.3x the single one, retried from the orbit at N where a coarse orbit fails.
  FloquetAtResolution at =
      resolution_study(problem, orbit_settings, options).floquet(with_error_bars, /*retry_from_N=*/true, with_series);
  const FloquetResult& result = at.result;
  const PeriodicOrbit& orbit = at.at_orbit.orbit;
  const ContactSummary& contacts = at.at_orbit.contacts;
  const HistoryGrid& grid = at.at_orbit.grid;  // the orbit's (aligned with its contacts where it could be)
  const LevelResult& at_N = at.at_N;
  const std::optional<ErrorBars>& bars = at.bars;
  nlohmann::json series;  // orbit_series = on: u_l at the start of step l of the map (the grid's node times)
  if (with_series)
    series = orbit_series_json(problem, at.at_orbit.sequence, grid.K, [&](long l) { return grid.node_time(l); });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::vector<double>& accuracy = at_N.accuracy;

  if (inv.json) {
    nlohmann::json json;
    json["model"] = problem.model_name;
    json["state_names"] = problem.state_names;
    json["N"] = problem.N;
    json["dimension"] = n;
    json["solver"] = to_string(result.solver);
    json["multipliers"] = multipliers_json(result.multipliers);
    add_resolution_json(json["multipliers"], result.multipliers, accuracy);
    if (bars) {
      add_error_bars_json(json["multipliers"], *bars);
      json["verdict"] = to_string(bars->verdict);
      json["error_bars"] = error_bars_json(*bars, at.error_bar_seconds);
    }
    json["seconds"] = seconds;
    json["orbit_seconds"] = at.orbit_seconds;
    json["eigensolver_seconds"] = result.seconds;
    json["operator_applications"] = result.operator_applications;
    json["converged"] = result.converged;
    json["restarts"] = result.restarts;
    json["residuals"] = result.residuals;  // |M v - mu v| / (|mu| |v|) per multiplier; [] for dense
    if (result.ncv > 0) {
      json["ncv"] = result.ncv;
      json["tol"] = options.tolerance;
      json["iterations"] = result.iterations;
      json["seed"] = options.seed;
    }
    json["h"] = problem.grid().h;
    json["steps_per_map"] = problem.grid().K;
    json["events"] = to_string(problem.events);
    json["grid"] = grid_json(grid);
    if (const nlohmann::json alignment = contact_alignment_json(at.at_orbit); !alignment.is_null())
      json["grid"]["contacts"] = alignment;
    json["jacobian"] = to_string(problem.jacobian);
    json["orbit_residual"] = orbit.residual;
    json["orbit_periods"] = orbit.maps;
    json["orbit"] = orbit_json(orbit, contacts);
    if (with_series) json["orbit_series"] = series;
    if (!result.note.empty()) json["note"] = result.note;
    inv.out << json.dump(2) << "\n";
  } else {
    inv.out << "delayspec floquet: model " << problem.model_label << ", " << grid.describe() << ", n = " << n << "\n";
    print_orbit(inv.out, orbit, contacts);
    inv.out << "leading " << result.multipliers.size() << " Floquet multipliers (" << to_string(result.solver) << ", "
            << result.operator_applications << " operator applications):\n";
    print_multipliers(inv.out, result.multipliers, accuracy);
    if (bars) print_error_bars(inv.out, result.multipliers, *bars);
    if (!result.residuals.empty()) {
      double worst = 0;
      for (double r : result.residuals) worst = std::max(worst, r);
      inv.out << "Krylov: ncv = " << result.ncv << ", " << result.converged << " converged, " << result.restarts
              << " restarts, largest residual |M v - mu v| / |mu| = " << worst << "\n";
    }
    if (!result.note.empty()) inv.out << "note: " << result.note << "\n";
    if (with_series) print_orbit_series(inv.out, problem, series);
    inv.out << "time: " << seconds << " s\n";
  }
  return 0;
}

}  // namespace delayspec::cli
