// delayspec simulate: trajectory, Poincare points and impact count over a time window, from the
// model's constant initial history (simulation.hpp for what is counted).
//
// Keys: t_end (default 10 periods), t_start (start of the recorded window, default 0),
// sample_every (grid points between trajectory samples, default 1), control_on_at (impact
// model: k = 0 before this time, the scene's k after; default 0 = control throughout),
// events_before_control (on | linear | off, default = events: the event handling before
// control_on_at, so that runs differing only in `events` after the switch start from the same
// state; the uncontrolled system is chaotic and would otherwise amplify the methods' difference).
// Output: text summary; --json one object; --out DIR writes trajectory.csv (t,x,v),
// poincare.csv (t,x,v) and impacts.csv (t,count: cumulative impacts).
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <limits>

#include <nlohmann/json.hpp>

#include "scene/output/output_directory.hpp"
#include "scene/commands/commands.hpp"
#include "delayspec/builtin_analyses.hpp"
#include "delayspec/simulation.hpp"
#include "scene/output/metadata.hpp"
#include "scene/output/output.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

namespace {

// "t,x,v": the time and the state's names.
std::string columns(const Problem& problem) {
  std::string c = "t";
  for (const auto& name : problem.state_names) c += "," + name;
  return c;
}

void write_points(std::ostream& s, const std::string& columns, const std::vector<double>& t,
                  const std::vector<Eigen::VectorXd>& y) {
  s << std::setprecision(std::numeric_limits<double>::max_digits10);
  s << columns << "\n";
  for (size_t i = 0; i < t.size(); ++i) {
    s << t[i];
    for (double c : y[i]) s << "," << c;
    s << "\n";
  }
}

nlohmann::json trajectory_json(const std::vector<double>& t, const std::vector<Eigen::VectorXd>& y) {
  nlohmann::json a = nlohmann::json::array();
  for (size_t i = 0; i < t.size(); ++i) {
    nlohmann::json row = {t[i]};
    for (double c : y[i]) row.push_back(c);
    a.push_back(row);
  }
  return a;
}

}  // namespace

int command_simulate(Config& config, const Invocation& inv) {
  const auto start = std::chrono::steady_clock::now();
  Problem problem = read_problem(config, 100);
  const HistoryGrid grid = problem.grid();
  const double period = grid.period;
  SimulationOptions options;
  options.t_end = config.get_double("t_end", 10 * period);
  options.t_start = config.get_double("t_start", 0);
  options.sample_every = config.get_int_in_range("sample_every", 1, 1, 1'000'000'000);
  const double control_on_at = config.get_double("control_on_at", 0);
  require_finite("control_on_at", control_on_at);
  if (control_on_at < 0) throw BadInput("`control_on_at = " + format_number(control_on_at) + "`: must be >= 0");
  // The control switch changes the impact model's feedback gain k (before_model below).
  if (control_on_at > 0 && !(problem.model && std::holds_alternative<ImpactModel>(*problem.model)))
    throw BadInput("`control_on_at = " + format_number(control_on_at) + "`: only for model = impact (it switches k)");
  Problem before_problem = problem;
  before_problem.events =
      parse_event_mode(config.get_choice("events_before_control", to_string(problem.events), event_mode_names()),
                       "events_before_control");
  if (before_problem.events != problem.events && !(control_on_at > 0))
    throw BadInput("`events_before_control = " + to_string(before_problem.events) + "`: needs control_on_at > 0");
  // A scene shared with the analysis commands (e.g. the default scene) may carry their keys.
  for (const char* key :
       {"nev", "solver", "ncv", "tol", "max_restarts", "seed", "residual_bound", "orbit", "orbit_tolerance",
        "orbit_max_periods", "orbit_max_iterations", "orbit_guess_periods", "exponents", "periods", "transient", "Ns"})
    config.mark_used(key);
  config.check_all_used();

  nlohmann::json json;
  std::ostringstream text;
  // The model before control_on_at: the impact model with k = 0 (checked above: impact only).
  std::shared_ptr<const ModelAnalyses> before_model;
  if (control_on_at > 0) {
    ImpactParameters p = std::get<ImpactModel>(*problem.model).parameters();
    p.k = 0;
    before_model = builtin_analyses(ImpactModel(p));
    options.switch_time = control_on_at;
  }
  const bool switching = problem.analyses->switches_in_state();
  const SimulationRecord<Eigen::Dynamic> rec =
      problem.analyses->simulate(before_problem.map_settings(), problem.map_settings(), options, before_model.get());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::vector<std::string> files;
  if (inv.out_dir) {
    const std::filesystem::path dir(*inv.out_dir);
    const std::string header = metadata_comment_lines(make_metadata(
        "simulate", inv.scene, config,
        {{"N", problem.N}, {"events", to_string(problem.events)}, {"jacobian", to_string(problem.jacobian)}}, seconds));
    OutputFile traj(inv, dir / "trajectory.csv");
    traj.stream() << header;
    write_points(traj.stream(), columns(problem), rec.t, rec.y);
    traj.commit();
    OutputFile poincare(inv, dir / "poincare.csv");
    poincare.stream() << header;
    write_points(poincare.stream(), columns(problem), rec.poincare_t, rec.poincare_y);
    poincare.commit();
    OutputFile impacts(inv, dir / "impacts.csv");
    impacts.stream() << header << std::setprecision(std::numeric_limits<double>::max_digits10) << "t,count\n";
    for (size_t i = 0; i < rec.impact_times.size(); ++i)
      impacts.stream() << rec.impact_times[i] << "," << i + 1 << "\n";
    impacts.commit();
    files = {traj.path().string(), poincare.path().string(), impacts.path().string()};
  }
  if (inv.arrays) (*inv.arrays)["trajectory"] = trajectory_json(rec.t, rec.y);
  if (inv.json) {
    json["model"] = problem.model_name;
    json["N"] = problem.N;
    json["h"] = grid.h;
    json["events"] = to_string(problem.events);
    json["grid"] = grid_json(grid);
    json["contact_substeps"] = problem.contact_substeps;
    json["t_start"] = options.t_start;
    json["t_end"] = options.t_end;
    json["steps"] = rec.steps;
    json["control_on_at"] = control_on_at;
    json["events_before_control"] = to_string(before_problem.events);
    json["impacts"] = rec.impact_times.size();
    json["impact_times"] = rec.impact_times;
    json["poincare"] = trajectory_json(rec.poincare_t, rec.poincare_y);
    json["columns"] = columns(problem);
    json["samples"] = rec.t.size();
    if (switching) json["max_H"] = rec.max_H;
    json["seconds"] = seconds;
    json["files"] = files;
  } else {
    text << "delayspec simulate: model " << problem.model_label << ", " << grid.describe() << ", events "
         << to_string(problem.events) << "\n";
    text << "window [" << options.t_start << ", " << options.t_end << "], " << rec.steps << " steps";
    if (control_on_at > 0)
      text << ", control (k) on from t = " << control_on_at << " (events " << to_string(before_problem.events)
           << " before)";
    text << "\n";
    if (switching)
      text << "impacts (entries into H > 0): " << rec.impact_times.size() << "; max H at grid points: " << rec.max_H
           << "\n";
    text << "Poincare points (t = m T): " << rec.poincare_t.size();
    if (!rec.poincare_y.empty()) text << ", last " << rec.poincare_y.back().transpose();
    text << "\n";
    for (const auto& f : files) text << "wrote " << f << "\n";
    text << "time: " << seconds << " s\n";
  }
  if (inv.json) inv.out << json.dump(2) << "\n";
  else inv.out << text.str();
  return 0;
}

}  // namespace delayspec::cli
