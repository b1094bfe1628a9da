#include "scene/commands/continue_equilibria.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "delayspec/equilibrium_branch.hpp"
#include "delayspec/family_equilibria.hpp"
#include "delayspec/errors.hpp"
#include "scene/output/branch_output.hpp"
#include "scene/output/metadata.hpp"
#include "scene/output/output.hpp"
#include "scene/output/output_directory.hpp"
#include "scene/output/progress.hpp"
#include "scene/problem/continue_settings.hpp"
#include "scene/problem/equilibrium_settings.hpp"
#include "scene/problem/floquet_settings.hpp"
#include "scene/problem/orbit_settings.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

namespace {

using nlohmann::json;

json state_json(const Eigen::VectorXd& y) { return std::vector<double>(y.data(), y.data() + y.size()); }

json branch_json(const Problem& problem, const std::string& key, const EquilibriumBranch& b, double seconds) {
  json j;
  j["model"] = problem.model_name;
  j["continue_key"] = key;
  j["continue_object"] = "equilibrium";
  j["state_names"] = problem.state_names;
  j["N"] = problem.N;  // of the starting roots only: every root and location is refined on c
  j["end"] = to_string(b.end);
  if (!b.failure.empty()) j["failure"] = b.failure;
  j["points"] = json::array();
  for (const EquilibriumPoint& p : b.points) {
    json pj;
    pj["parameter"] = p.parameter;
    pj["equilibrium"] = state_json(p.equilibrium.state);
    pj["roots"] = characteristic_roots_json(p.equilibrium.roots);
    pj["unstable"] = p.equilibrium.unstable;
    pj["critical"] = p.equilibrium.critical;
    pj["stable"] = p.equilibrium.stable();
    pj["corrector_iterations"] = p.corrector_iterations;
    j["points"].push_back(pj);
  }
  j["bifurcations"] = json::array();
  for (const EquilibriumBifurcation& f : b.bifurcations) {
    json fj;
    fj["type"] = to_string(f.type);
    fj["parameter"] = f.parameter;
    fj["parameter_bound"] = f.parameter_bound;
    fj["equilibrium"] = state_json(f.state);
    fj["root"] = characteristic_roots_json({f.root})[0];
    if (f.type == EquilibriumBifurcationType::hopf) {
      fj["omega"] = f.omega;
      fj["period"] = f.period;
      if (f.normal_form) {
        const HopfNormalForm& n = *f.normal_form;
        fj["l1"] = std::isfinite(n.l1) ? json(n.l1) : json(nullptr);
        fj["l1_bound"] = std::isfinite(n.l1_bound) ? json(n.l1_bound) : json(nullptr);
        fj["criticality"] = to_string(n.criticality);
        if (!n.note.empty()) fj["criticality_note"] = n.note;
      }
    }
    fj["evaluations"] = f.evaluations;
    j["bifurcations"].push_back(fj);
  }
  j["seconds"] = seconds;
  return j;
}

std::string points_csv(const std::string& header, const Problem& problem, const EquilibriumBranch& b) {
  // a column pair per root of the point with the most (the branch tracks more roots where more are
  // unstable: equilibrium_branch.hpp)
  size_t nroots = 0;
  for (const EquilibriumPoint& p : b.points) nroots = std::max(nroots, p.equilibrium.roots.size());
  std::ostringstream rows;
  rows << header << "parameter,stable,unstable";
  for (const std::string& name : problem.state_names) rows << "," << name;
  for (size_t k = 1; k <= nroots; ++k) rows << ",lambda" << k << "_re,lambda" << k << "_im";
  rows << "\n";
  for (const EquilibriumPoint& p : b.points) {
    rows << csv_number(p.parameter) << "," << (p.equilibrium.stable() ? 1 : 0) << "," << p.equilibrium.unstable;
    for (long i = 0; i < p.equilibrium.state.size(); ++i) rows << "," << csv_number(p.equilibrium.state[i]);
    for (size_t k = 0; k < nroots; ++k) {
      const bool has = k < p.equilibrium.roots.size();
      rows << "," << csv_number(has ? p.equilibrium.roots[k].value.real() : NAN) << ","
           << csv_number(has ? p.equilibrium.roots[k].value.imag() : NAN);
    }
    rows << "\n";
  }
  return rows.str();
}

std::string equilibrium_bifurcations_csv(const std::string& header, const EquilibriumBranch& b) {
  std::ostringstream rows;
  rows << header << "type,parameter,parameter_bound,omega,period,lambda_re,lambda_im,l1,l1_bound,criticality\n";
  for (const EquilibriumBifurcation& f : b.bifurcations) {
    const HopfNormalForm* n = f.normal_form ? &*f.normal_form : nullptr;
    rows << to_string(f.type) << "," << csv_number(f.parameter) << "," << csv_number(f.parameter_bound) << ","
         << csv_number(f.type == EquilibriumBifurcationType::hopf ? f.omega : NAN) << ","
         << csv_number(f.type == EquilibriumBifurcationType::hopf ? f.period : NAN) << ","
         << csv_number(f.root.value.real()) << "," << csv_number(f.root.value.imag()) << ","
         << csv_number(n ? n->l1 : NAN) << "," << csv_number(n ? n->l1_bound : NAN) << ","
         << (n ? to_string(n->criticality) : "") << "\n";
  }
  return rows.str();
}

// Every Hopf branch's failures on one line (empty: none).
std::string hopf_failures(const std::vector<HopfOrbitBranch>& branches, const std::vector<int>& Ns, const std::string& key) {
  std::string failures;
  for (const HopfOrbitBranch& b : branches)
    for (size_t i = 0; i < b.levels.size(); ++i)
      if (!b.levels[i].failure.empty())
        failures += (failures.empty() ? "" : "; ") + std::string("orbits from the Hopf point at ") + key + " = " +
                    format_number(b.hopf->parameter) + ", N = " + std::to_string(Ns[i]) + ": " + b.levels[i].failure;
  return failures;
}

json hopf_branches_json(const std::vector<HopfOrbitBranch>& branches, const std::vector<int>& Ns) {
  json list = json::array();
  for (const HopfOrbitBranch& b : branches) {
    json bj;
    bj["from_parameter"] = b.hopf->parameter;
    bj["omega"] = b.hopf->omega;
    bj["period"] = b.hopf->period;
    bj["N"] = Ns.back();
    bj["Ns"] = Ns;
    bj["end"] = to_string(b.finest().end);
    if (!b.finest().failure.empty()) bj["failure"] = b.finest().failure;
    bj["points"] = points_json(b.finest().points);
    bj["bifurcations"] = bifurcations_json(b.estimates, b.finest());
    list.push_back(bj);
  }
  return list;
}

// The orbits' size in the table: the amplitude (max - min)/2 of the state component `name`.
void print_hopf_branches(std::ostream& os, const std::string& key, const std::vector<HopfOrbitBranch>& branches,
                         const std::vector<int>& Ns, size_t component, const std::string& name) {
  char line[256];
  for (const HopfOrbitBranch& b : branches) {
    const ContinuationResult& r = b.finest();
    os << "orbits from the Hopf point at " << key << " = " << format_number(b.hopf->parameter) << " (N = " << Ns.back()
       << "): " << r.points.size() << " points, ended at `" << to_string(r.end) << "`\n";
    const std::string amplitude = "(max - min)/2 of " + name;
    std::snprintf(line, sizeof line, "  %16s  %16s  %12s  %8s  %20s\n", key.c_str(), "period", "|mu_1|", "unstable",
                  amplitude.c_str());
    os << line;
    for (const ContinuationPoint& p : r.points) {
      std::snprintf(line, sizeof line, "  %16.10g  %16.10g  %12.8f  %8d  %20.8g\n", p.parameter, p.period,
                    p.multipliers.empty() ? NAN : std::abs(p.multipliers[0]), p.unstable,
                    (p.measures.max.at(component) - p.measures.min.at(component)) / 2);
      os << line;
    }
    os << "  bifurcations: " << b.estimates.size() << "\n";
    for (const BifurcationEstimate& e : b.estimates) {
      os << "    " << to_string(e.type) << " at " << key << " = " << format_number(e.parameter);
      if (e.Ns.size() > 1)
        os << "; extrapolated " << format_number(e.extrapolated) << " +- " << format_number(e.error_estimate, 2)
           << " (order " << format_number(e.observed_order, 3) << ")";
      os << "\n";
    }
  }
}

// "first Lyapunov coefficient l1 = -0.2141309224 +- 3.1e-13: supercritical (a stable orbit is born)"
std::string criticality_line(const HopfNormalForm& n) {
  if (!n.note.empty()) return n.note;
  std::string line = "first Lyapunov coefficient l1 = " + format_number(n.l1) + " +- " + format_number(n.l1_bound, 2) +
                     ": " + to_string(n.criticality);
  switch (n.criticality) {
    case HopfCriticality::supercritical: return line + " (a stable orbit is born)";
    case HopfCriticality::subcritical: return line + " (an unstable orbit collapses onto the equilibrium)";
    case HopfCriticality::degenerate: return line + " (l1 = 0 within its bar: the cubic term does not decide)";
  }
  return line;
}

// The table shows the state component `component` of each equilibrium.
void print_branch(std::ostream& os, const Problem& problem, size_t component, const std::string& key,
                  const EquilibriumBranchOptions& o, const EquilibriumBranch& b, double seconds) {
  os << "delayspec continue: model " << problem.model_label << ", equilibria in " << key << " from "
     << format_number(o.from) << " to " << format_number(o.to) << "\nbranch: " << b.points.size()
     << " points, ended at `" << to_string(b.end) << "`\n";
  char line[256];
  std::snprintf(line, sizeof line, "  %16s  %16s  %16s  %16s  %8s\n", key.c_str(),
                problem.state_names.at(component).c_str(), "Re lambda_1", "Im lambda_1", "unstable");
  os << line;
  for (const EquilibriumPoint& p : b.points) {
    const auto& r = p.equilibrium;
    std::snprintf(line, sizeof line, "  %16.10g  %16.10g  %+16.9e  %16.9e  %8d\n", p.parameter,
                  r.state[static_cast<long>(component)], r.roots.empty() ? NAN : r.roots[0].value.real(),
                  r.roots.empty() ? NAN : r.roots[0].value.imag(), r.unstable);
    os << line;
  }
  os << "bifurcations: " << b.bifurcations.size() << " (located on the exact characteristic function)\n";
  for (const EquilibriumBifurcation& f : b.bifurcations) {
    os << "  " << to_string(f.type) << " at " << key << " = " << format_number(f.parameter) << " +- "
       << format_number(f.parameter_bound, 2);
    if (f.type == EquilibriumBifurcationType::hopf)
      os << ", omega = " << format_number(f.omega) << ", period of the orbit born 2 pi / omega = "
         << format_number(f.period);
    if (f.normal_form) os << "\n    " << criticality_line(*f.normal_form);
    os << "\n";
  }
  os << "time: " << seconds << " s\n";
}

// What the command reads and checks before any work.
struct EquilibriaRun {
  ContinueSettings settings;
  bool from_hopf = false;  // continue_switch: the orbits born at Hopf points
  Problem problem;         // at continue_from
  int index = -1;          // the continued key's parameter in problem.family
  EquilibriumSettings eq;
  ContinuationOptions orbit_options;  // the orbit branches': the range with its defaults, nev, orbit_tolerance
  std::vector<int> Ns;                // continue_Ns, or the one level N
  size_t component = 0;               // plot_component: the state component the tables show
};

EquilibriaRun read_equilibria_run(Config& config) {
  EquilibriaRun run;
  run.settings = read_continue_settings(config);
  run.from_hopf = run.settings.switch_period_doubling;
  if (!run.settings.Ns.empty() && !run.from_hopf)
    throw BadInput("`continue_Ns` with `continue_object = equilibrium` and no `continue_switch = true`: an "
                   "equilibrium's bifurcations are located on the exact characteristic function, with no "
                   "discretisation error to extrapolate (continue_Ns gives the error bars of the orbit branches "
                   "born at its Hopf points)");
  run.problem = read_problem(config, 100, ModelNeed::autonomous);
  run.eq = read_equilibrium_settings(config, run.problem);
  run.component = read_plot_component(config, run.problem);
  run.orbit_options = run.settings.options;
  static_cast<BranchRange&>(run.orbit_options) = checked_range(run.settings.options);
  if (run.from_hopf) {
    run.orbit_options.floquet = read_floquet_options(config);
    run.orbit_options.newton.tolerance = read_orbit_settings(config).newton.tolerance;
    run.orbit_options.step_options = step_options(run.problem);
  }
  run.problem = starting_problem(run.problem, config,
                                 {{"continue_key", run.settings.key, run.settings.options.from, "continue_from"}});
  run.index = family_parameter(run.problem, "continue_key", run.settings.key);
  config.check_all_used();
  require_autonomous(run.problem);
  if (run.from_hopf && run.problem.analyses->is_linear())
    throw BadInput("`continue_switch = true` with `model = " + run.problem.model_name +
                   "`: a linear model's Hopf point has a continuum of periodic orbits, none isolated, so no branch "
                   "of orbits to follow");
  run.Ns = run.settings.Ns.empty() ? std::vector<int>{run.problem.N} : run.settings.Ns;
  return run;
}

// --out DIR: equilibria.csv, equilibrium_bifurcations.csv, hopf_branch_K.csv and
// hopf_bifurcations_K.csv, continue.json, marked incomplete after a failure.
void write_equilibria_files(const Invocation& inv, const Config& config, const EquilibriaRun& run,
                            const EquilibriumBranch& branch, const std::vector<HopfOrbitBranch>& orbits,
                            const std::string& failures, const json& j, double seconds) {
  const std::filesystem::path dir(*inv.out_dir);
  OutputMetadata metadata = make_metadata("continue", inv.scene, config, j, seconds);
  metadata.parameters.erase(run.settings.key);  // per row
  std::string header = metadata_comment_lines(metadata);
  if (!failures.empty()) header += "# INCOMPLETE: a branch ended in a failure: " + failures + "\n";
  write_output(inv, dir / "equilibria.csv", points_csv(header, run.problem, branch));
  write_output(inv, dir / "equilibrium_bifurcations.csv", equilibrium_bifurcations_csv(header, branch));
  for (size_t i = 0; i < orbits.size(); ++i) {
    const std::string n = std::to_string(i + 1);
    write_output(inv, dir / ("hopf_branch_" + n + ".csv"),
                 branch_csv(header, orbits[i].finest(), run.orbit_options.floquet.nev));
    write_output(inv, dir / ("hopf_bifurcations_" + n + ".csv"),
                 bifurcations_csv(header, orbits[i].estimates, orbits[i].finest()));
  }
  json file = j;
  file["metadata"] = metadata_json(metadata);
  write_output(inv, dir / "continue.json", file.dump(2) + "\n");
}

}  // namespace

int continue_equilibria(Config& config, const Invocation& inv) {
  const auto start = std::chrono::steady_clock::now();
  const EquilibriaRun run = read_equilibria_run(config);
  const std::string& key = run.settings.key;
  EquilibriumBranchOptions o;
  static_cast<BranchRange&>(o) = run.settings.options;
  o.newton_tolerance = run.eq.options.tolerance;
  o.nroots = run.eq.options.nroots;
  Progress progress(inv.err, "continue", 0, inv.quiet);
  o.on_point = [&progress] { progress.add(); };
  const AnalysesAt at = analyses_along(run.problem, run.index);
  const EquilibriumBranch branch = continue_equilibrium(equilibria_along(at, run.eq.options), run.eq.guess, o);
  ContinuationOptions orbit_options = run.orbit_options;
  orbit_options.on_point = [&progress](const ContinuationPoint&) { progress.add(); };
  const std::vector<HopfOrbitBranch> orbits =
      run.from_hopf ? orbits_from_hopf_points(branch, at, run.Ns, orbit_options) : std::vector<HopfOrbitBranch>{};
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::string failures = branch.failure;
  const std::string orbit_failures = hopf_failures(orbits, run.Ns, key);
  if (!orbit_failures.empty()) failures += (failures.empty() ? "" : "; ") + orbit_failures;

  json j = branch_json(run.problem, key, branch, seconds);
  if (run.from_hopf) j["hopf_branches"] = hopf_branches_json(orbits, run.Ns);
  if (inv.out_dir) write_equilibria_files(inv, config, run, branch, orbits, failures, j, seconds);
  if (!failures.empty()) {
    inv.err << "delayspec continue: numerical failure: " << failures
            << (inv.out_dir ? "; the branch so far is in " + *inv.out_dir : std::string()) << "\n";
    return 3;
  }
  if (inv.json) {
    inv.out << j.dump(2) << "\n";
  } else {
    const std::string& name = run.problem.state_names.at(run.component);
    print_branch(inv.out, run.problem, run.component, key, o, branch, seconds);
    print_hopf_branches(inv.out, key, orbits, run.Ns, run.component, name);
  }
  return 0;
}

}  // namespace delayspec::cli
