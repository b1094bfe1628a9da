// delayspec continue: pseudo-arclength continuation of the periodic orbit in one model key, with
// its bifurcations located and, with continue_Ns, extrapolated to N -> infinity (issue 15;
// continuation.hpp; docs/continuation.md).
//
// The start: the orbit at continue_from found as `floquet` finds it (orbit = simulate | newton;
// linear models: the zero orbit), then corrected by the continuation's own Newton. With
// continue_Ns the whole branch is computed at every N of the list; the branch reported is the
// finest one, each bifurcation carries its location at every N where it was found.
//
// Files with --out DIR (after the metadata comment lines):
//   branch.csv         one row per point: parameter, stability, |mu_1|, the measures, the multipliers
//   bifurcations.csv   one row per bifurcation: type, location at the finest N, extrapolation,
//                      error estimate, angle, locations by N
//   continue.json  the --json result
// A branch that ends in a failure (a step that cannot be reduced further) is written as far as it
// got, the failure named in the files and on stderr, exit 3.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "scene/output/branch_output.hpp"
#include "scene/output/output_directory.hpp"
#include "scene/commands/commands.hpp"
#include "scene/commands/continue_equilibria.hpp"
#include "scene/problem/autonomous_floquet.hpp"
#include "scene/problem/continue_settings.hpp"
#include "delayspec/branch_verdicts.hpp"
#include "delayspec/continuation.hpp"
#include "delayspec/error_expansion.hpp"
#include "scene/problem/floquet_settings.hpp"
#include "scene/output/metadata.hpp"
#include "scene/problem/orbit_settings.hpp"
#include "scene/output/output.hpp"
#include "scene/problem/problem.hpp"
#include "scene/output/progress.hpp"

namespace delayspec::cli {

namespace {

using nlohmann::json;

// What the command reads and checks before any work; the keys are read in this order (--help lists them so).
struct ContinueRun {
  ContinueSettings settings;
  OrbitSettings orbit_settings;
  ContinuationOptions options;
  Problem problem;         // at continue_from
  int index = -1;          // the continued key's parameter in problem.family
  std::vector<int> Ns;     // continue_Ns, or the one level N
  std::optional<double> period_guess;  // an autonomous orbit of unknown period (issue 60 item 5)
  size_t component = 0;                // plot_component: the state component the table shows
};

// Reads the keys and the problem at the start value, and rejects what continue cannot take.
ContinueRun read_continue_run(Config& config) {
  ContinueRun run;
  run.settings = read_continue_settings(config);
  run.orbit_settings = read_orbit_settings(config);
  run.options = run.settings.options;
  run.options.floquet = read_floquet_options(config);
  run.options.newton.tolerance = run.orbit_settings.newton.tolerance;       // the corrector's relative residual
  run.options.start_iterations = run.orbit_settings.newton.max_iterations;  // the first point's Newton
  const Problem scene = read_problem(config, 100);
  run.period_guess = read_period_guess(config, scene);
  run.component = read_plot_component(config, scene);
  run.problem = starting_problem(scene, config, {{"continue_key", run.settings.key, run.options.from, "continue_from"}});
  run.index = family_parameter(run.problem, "continue_key", run.settings.key);
  config.check_all_used();
  if (run.period_guess && run.settings.switch_period_doubling)
    throw BadInput("`continue_switch = true` with `period_guess`: the period-2 branch of an orbit of unknown period "
                   "is not followed yet (its period doublings are located and extrapolated)");
  run.Ns = run.settings.Ns.empty() ? std::vector<int>{run.problem.N} : run.settings.Ns;
  return run;
}

// One level N with the continued parameter at p (the model's family: no scene read), and the
// options' discretisation taken from it.
Problem level_at(const ContinueRun& run, double p, int N, ContinuationOptions& options, Progress& progress) {
  std::string rejected;
  const std::optional<Problem> level =
      problem_at(run.problem, ProblemFamily::with(run.problem.parameter_values, run.index, p), N, rejected);
  if (!level) throw BadInput(rejected);
  options.N = N;
  options.periods_per_map = level->orbit_period;
  options.step_options = step_options(*level);
  options.on_point = [&progress](const ContinuationPoint&) { progress.add(); };
  return *level;
}

// The branch at one N: the start orbit at `from`, then continue_orbit; with period_guess the
// orbit of unknown period found as `floquet` finds it, then continue_autonomous_orbit.
ContinuationResult branch_at(const ContinueRun& run, ContinuationOptions options, int N, Progress& progress) {
  const Problem level = level_at(run, options.from, N, options, progress);
  const AnalysesAt at = analyses_along(level, run.index);
  if (run.period_guess)
    return level.analyses->continue_autonomous_orbit(
        at, autonomous_orbit_options(run.orbit_settings, step_options(level), N, *run.period_guess), options);
  return level.analyses->continue_orbit(at, run.orbit_settings, options);
}

// The period-2 branch from the period doubling `pd` of the branch at N (continue_switch).
ContinuationResult switched_at(const ContinueRun& run, ContinuationOptions options, int N, const Bifurcation& pd,
                               Progress& progress) {
  const Problem level = level_at(run, pd.parameter, N, options, progress);
  return level.analyses->continue_period_doubled(analyses_along(level, run.index), pd, options);
}

// The computed branches: one per N, the period-2 branches of the finest one, the extrapolated
// bifurcations, and every failure named on one line (empty: none).
struct ContinueOutcome {
  std::vector<ContinuationResult> levels;  // by N; the reported branch is the last
  std::vector<BifurcationEstimate> estimates;
  BranchVerdicts verdicts;  // of the finest branch's points
  std::vector<ContinuationResult> switched;
  std::vector<double> switched_from;  // each switched branch's period doubling
  std::string failures;
  const ContinuationResult& branch() const { return levels.back(); }
};

// Computes the branch at every N, extrapolates its bifurcations, and (continue_switch) the
// period-2 branches from the finest branch's period doublings.
ContinueOutcome compute_continue(const ContinueRun& run, const Invocation& inv) {
  const ContinuationOptions& options = run.options;
  ContinueOutcome out;
  Progress progress(inv.err, "continue", 0, inv.quiet);
  for (int N : run.Ns)
    out.levels.push_back(branch_at(run, options, N, progress));
  std::vector<std::vector<Bifurcation>> by_N;
  for (const auto& r : out.levels) by_N.push_back(r.bifurcations);
  // the floor of the bars: the locations' tolerance (its default filled in), or the refined one
  const ContinuationOptions checked = continuation_detail::checked_options(options);
  const double tolerance = checked.refine_tolerance > 0 ? checked.refine_tolerance : checked.tolerance;
  out.estimates = extrapolate_bifurcations(run.Ns, by_N, tolerance,
                                           error_expansion(*run.problem.analyses, step_options(run.problem)));
  out.verdicts = branch_verdicts(out.branch().points, out.estimates, run.Ns, by_N);
  // continue_switch: the period-2 branch of every period doubling on the finest branch.
  if (run.settings.switch_period_doubling)
    for (const Bifurcation& b : out.branch().bifurcations)
      if (b.type == BifurcationType::period_doubling) {
        out.switched.push_back(switched_at(run, options, run.Ns.back(), b, progress));
        out.switched_from.push_back(b.parameter);
      }
  progress.finish();
  for (size_t i = 0; i < out.switched.size(); ++i)
    if (!out.switched[i].failure.empty())
      out.failures += (out.failures.empty() ? "" : "; ") + std::string("period-2 branch from ") +
                      format_number(out.switched_from[i]) + ": " + out.switched[i].failure;
  for (size_t i = 0; i < out.levels.size(); ++i)
    if (!out.levels[i].failure.empty())
      out.failures += (out.failures.empty() ? "" : "; ") + std::string("N = ") + std::to_string(run.Ns[i]) + ": " +
                      out.levels[i].failure;
  return out;
}

// The period-2 branches (continue_switch), at the finest N.
json switched_json(const ContinueRun& run, const ContinueOutcome& out) {
  json list = json::array();
  for (size_t i = 0; i < out.switched.size(); ++i) {
    json sj;
    sj["from_parameter"] = out.switched_from[i];
    sj["orbit_period"] = 2 * run.problem.orbit_period;
    sj["N"] = run.Ns.back();
    sj["end"] = to_string(out.switched[i].end);
    sj["points"] = points_json(out.switched[i].points);
    sj["bifurcations"] = json::array();
    for (const Bifurcation& b : out.switched[i].bifurcations)
      sj["bifurcations"].push_back({{"type", to_string(b.type)},
                                    {"parameter", b.parameter},
                                    {"angle", b.angle},
                                    {"multipliers", multipliers_json(b.multipliers)},
                                    {"note", b.note}});
    list.push_back(sj);
  }
  return list;
}

// The --json result (also continue.json's body).
json continue_json(const ContinueRun& run, const ContinueOutcome& out, double seconds) {
  const ContinuationResult& branch = out.branch();
  json j;
  j["model"] = run.problem.model_name;
  j["state_names"] = run.problem.state_names;  // the measures' components, in order
  j["continue_key"] = run.settings.key;
  j["N"] = run.Ns.back();
  j["Ns"] = run.Ns;
  j["events"] = to_string(run.problem.events);
  j["jacobian"] = to_string(run.problem.jacobian);
  if (run.period_guess) j["period_guess"] = *run.period_guess;
  j["end"] = to_string(branch.end);
  if (!out.failures.empty()) j["failure"] = out.failures;
  j["points"] = points_json(branch.points, out.verdicts.verdicts);
  j["verdicts_note"] = out.verdicts.note;
  j["bifurcations"] = bifurcations_json(out.estimates, branch);
  if (run.settings.switch_period_doubling) j["switched"] = switched_json(run, out);
  json cost;
  cost["points"] = branch.points.size();
  cost["newton_iterations"] = branch.newton_iterations;
  cost["unknowns"] = branch.unknowns;
  cost["factorisations"] = branch.factorisations;
  cost["gmres_products"] = branch.gmres_products;
  cost["krylov_solves"] = branch.krylov_solves;
  cost["newton_seconds"] = branch.newton_seconds;
  cost["krylov_seconds"] = branch.krylov_seconds;
  cost["locate_seconds"] = branch.locate_seconds;
  cost["branch_seconds"] = branch.seconds;
  j["cost_finest_N"] = cost;
  j["seconds"] = seconds;
  return j;
}

// --out DIR: branch.csv, bifurcations.csv and continue.json, marked incomplete after a failure.
void write_continue_files(const Invocation& inv, const Config& config, const ContinueRun& run,
                          const ContinueOutcome& out, const json& j, double seconds) {
  const std::filesystem::path dir(*inv.out_dir);
  OutputMetadata metadata = make_metadata("continue", inv.scene, config, j, seconds);
  metadata.parameters.erase(run.settings.key);  // per row (plot labels the x axis with continue_key)
  std::string header = metadata_comment_lines(metadata);
  if (!out.failures.empty()) header += "# INCOMPLETE: the branch ended in a failure: " + out.failures + "\n";
  write_output(inv, dir / "branch.csv",
               branch_csv(header, out.branch(), run.options.floquet.nev, out.verdicts.verdicts));
  write_output(inv, dir / "bifurcations.csv", bifurcations_csv(header, out.estimates, out.branch()));
  json file = j;
  file["metadata"] = metadata_json(metadata);
  write_output(inv, dir / "continue.json", file.dump(2) + "\n");
}

// The text report: the branch's points, the bifurcations, the time.
void print_continue(std::ostream& os, const ContinueRun& run, const ContinueOutcome& out, double seconds) {
  const ContinuationResult& branch = out.branch();
  const std::string& key = run.settings.key;
  char line[256];
  os << "delayspec continue: model " << run.problem.model_label << ", " << key << " from "
     << format_number(run.options.from) << " to " << format_number(run.options.to) << ", N = ";
  for (size_t i = 0; i < run.Ns.size(); ++i) os << (i ? "," : "") << run.Ns[i];
  os << "\nbranch (N = " << run.Ns.back() << "): " << branch.points.size() << " points, ended at `"
     << to_string(branch.end) << "`\n";
  // an orbit of unknown period: its period too (the multipliers are the others than the trivial one)
  const bool with_period = run.period_guess.has_value();
  const std::string max = "max " + run.problem.state_names.at(run.component);
  std::snprintf(line, sizeof line, "  %16s  %12s  %8s  %14s%s  %s\n", key.c_str(), "|mu_1|", "unstable", max.c_str(),
                with_period ? "            period" : "", "verdict");
  os << line;
  for (size_t i = 0; i < branch.points.size(); ++i) {
    const ContinuationPoint& p = branch.points[i];
    char period[32] = "";
    if (with_period) std::snprintf(period, sizeof period, "  %16.10g", p.period);
    std::snprintf(line, sizeof line, "  %16.10g  %12.8f  %8d  %14.8g%s  %s\n", p.parameter,
                  p.multipliers.empty() ? NAN : std::abs(p.multipliers[0]), p.unstable,
                  p.measures.max.at(run.component), period, to_string(out.verdicts.verdicts.at(i)).c_str());
    os << line;
  }
  os << "verdicts: " << out.verdicts.note << "\n";
  os << "bifurcations: " << out.estimates.size() << "\n";
  for (size_t b = 0; b < out.estimates.size(); ++b) {
    const BifurcationEstimate& e = out.estimates[b];
    os << "  " << to_string(e.type) << " at " << key << " = " << format_number(e.parameter);
    if (e.type != BifurcationType::grazing) os << ", angle " << e.angle << " (" << e.angle / std::numbers::pi << " pi)";
    if (e.Ns.size() > 1)
      os << "; extrapolated " << format_number(e.extrapolated) << " +- " << e.error_estimate << " (order "
         << e.observed_order << ")";
    os << "\n";
    if (!branch.bifurcations[b].note.empty()) os << "    note: " << branch.bifurcations[b].note << "\n";
  }
  os << "time: " << seconds << " s (finest N: Newton " << branch.newton_seconds << " s, Krylov "
     << branch.krylov_seconds << " s)\n";
}

}  // namespace

int command_continue(Config& config, const Invocation& inv) {
  // continue_object = equilibrium: the branch of equilibria (continue_equilibria.hpp)
  if (config.get_choice("continue_object", "orbit", {"orbit", "equilibrium"}) == "equilibrium")
    return continue_equilibria(config, inv);
  const auto start = std::chrono::steady_clock::now();
  const ContinueRun run = read_continue_run(config);
  // An autonomous model has no forcing period: what is followed is the fixed point of the map
  // over the sampling period T (an equilibrium, or an orbit whose period divides T), wherever
  // the history leads; said, so that it is not taken for the orbit (issue 61 item 7).
  if (const std::string note = autonomous_fixed_point_note(run.problem);
      !note.empty() && !run.period_guess && !inv.quiet)
    inv.err << "delayspec continue: note: " << note << "\n";
  const ContinueOutcome out = compute_continue(run, inv);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const json j = continue_json(run, out, seconds);
  if (inv.out_dir) write_continue_files(inv, config, run, out, j, seconds);
  if (!out.failures.empty()) {
    inv.err << "delayspec continue: numerical failure: " << out.failures
            << (inv.out_dir ? "; the branch so far is in " + *inv.out_dir : std::string()) << "\n";
    return 3;
  }
  if (inv.json) {
    inv.out << j.dump(2) << "\n";
    return 0;
  }
  print_continue(inv.out, run, out, seconds);
  return 0;
}

}  // namespace delayspec::cli
