#include "scene/commands/continue_equilibria.hpp"

#include <chrono>
#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

#include "delayspec/equilibrium_branch.hpp"
#include "delayspec/errors.hpp"
#include "scene/output/metadata.hpp"
#include "scene/output/output.hpp"
#include "scene/output/output_directory.hpp"
#include "scene/output/progress.hpp"
#include "scene/problem/continue_settings.hpp"
#include "scene/problem/equilibrium_settings.hpp"
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
    }
    fj["evaluations"] = f.evaluations;
    j["bifurcations"].push_back(fj);
  }
  j["seconds"] = seconds;
  return j;
}

std::string points_csv(const std::string& header, const Problem& problem, const EquilibriumBranch& b, int nroots) {
  std::ostringstream rows;
  rows << header << "parameter,stable,unstable";
  for (const std::string& name : problem.state_names) rows << "," << name;
  for (int k = 1; k <= nroots; ++k) rows << ",lambda" << k << "_re,lambda" << k << "_im";
  rows << "\n";
  for (const EquilibriumPoint& p : b.points) {
    rows << csv_number(p.parameter) << "," << (p.equilibrium.stable() ? 1 : 0) << "," << p.equilibrium.unstable;
    for (long i = 0; i < p.equilibrium.state.size(); ++i) rows << "," << csv_number(p.equilibrium.state[i]);
    for (int k = 0; k < nroots; ++k) {
      const bool has = static_cast<size_t>(k) < p.equilibrium.roots.size();
      rows << "," << csv_number(has ? p.equilibrium.roots[k].value.real() : NAN) << ","
           << csv_number(has ? p.equilibrium.roots[k].value.imag() : NAN);
    }
    rows << "\n";
  }
  return rows.str();
}

std::string bifurcations_csv(const std::string& header, const EquilibriumBranch& b) {
  std::ostringstream rows;
  rows << header << "type,parameter,parameter_bound,omega,period,lambda_re,lambda_im\n";
  for (const EquilibriumBifurcation& f : b.bifurcations)
    rows << to_string(f.type) << "," << csv_number(f.parameter) << "," << csv_number(f.parameter_bound) << ","
         << csv_number(f.type == EquilibriumBifurcationType::hopf ? f.omega : NAN) << ","
         << csv_number(f.type == EquilibriumBifurcationType::hopf ? f.period : NAN) << ","
         << csv_number(f.root.value.real()) << "," << csv_number(f.root.value.imag()) << "\n";
  return rows.str();
}

void print_branch(std::ostream& os, const Problem& problem, const std::string& key, const EquilibriumBranchOptions& o,
                  const EquilibriumBranch& b, double seconds) {
  os << "delayspec continue: model " << problem.model_name << ", equilibria in " << key << " from "
     << format_number(o.from) << " to " << format_number(o.to) << "\nbranch: " << b.points.size()
     << " points, ended at `" << to_string(b.end) << "`\n";
  char line[256];
  std::snprintf(line, sizeof line, "  %16s  %16s  %16s  %16s  %8s\n", key.c_str(),
                (problem.state_names.front()).c_str(), "Re lambda_1", "Im lambda_1", "unstable");
  os << line;
  for (const EquilibriumPoint& p : b.points) {
    const auto& r = p.equilibrium;
    std::snprintf(line, sizeof line, "  %16.10g  %16.10g  %+16.9e  %16.9e  %8d\n", p.parameter, r.state[0],
                  r.roots.empty() ? NAN : r.roots[0].value.real(), r.roots.empty() ? NAN : r.roots[0].value.imag(),
                  r.unstable);
    os << line;
  }
  os << "bifurcations: " << b.bifurcations.size() << " (located on the exact characteristic function)\n";
  for (const EquilibriumBifurcation& f : b.bifurcations) {
    os << "  " << to_string(f.type) << " at " << key << " = " << format_number(f.parameter) << " +- "
       << format_number(f.parameter_bound, 2);
    if (f.type == EquilibriumBifurcationType::hopf)
      os << ", omega = " << format_number(f.omega) << ", period of the orbit born 2 pi / omega = "
         << format_number(f.period);
    os << "\n";
  }
  os << "time: " << seconds << " s\n";
}

}  // namespace

int continue_equilibria(Config& config, const Invocation& inv) {
  const auto start = std::chrono::steady_clock::now();
  const ContinueSettings settings = read_continue_settings(config);
  if (!settings.Ns.empty())
    throw BadInput("`continue_Ns` with `continue_object = equilibrium`: an equilibrium's bifurcations are located on "
                   "the exact characteristic function, with no discretisation error to extrapolate");
  if (settings.switch_period_doubling)
    throw BadInput("`continue_switch = true` with `continue_object = equilibrium`: following the orbits born at a "
                   "Hopf point is not implemented yet (issue 35, item 4)");
  config.set(settings.key, format_number(settings.options.from), "continue_from");
  const Problem problem = read_problem(config, 100);
  const EquilibriumSettings eq = read_equilibrium_settings(config, problem);
  config.check_all_used();
  require_autonomous(problem);

  EquilibriumBranchOptions o;
  static_cast<BranchRange&>(o) = settings.options;
  o.newton_tolerance = eq.options.tolerance;
  Progress progress(inv.err, "continue", 0, inv.quiet);
  o.on_point = [&progress] { progress.add(); };
  const AnalysesAt at = analyses_with_key(config, settings.key);
  const EquilibriumFamily family{
      [&at](const Eigen::VectorXd& y, double p) { return at(p)->at_constant_history(y); },
      [&at, &eq](const Eigen::VectorXd& guess, double p) { return at(p)->equilibrium(guess, eq.options); }};
  const EquilibriumBranch branch = continue_equilibrium(family, eq.guess, o);
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const json j = branch_json(problem, settings.key, branch, seconds);
  if (inv.out_dir) {
    const std::filesystem::path dir(*inv.out_dir);
    OutputMetadata metadata = make_metadata("continue", inv.scene, config, j, seconds);
    metadata.parameters.erase(settings.key);  // per row
    std::string header = metadata_comment_lines(metadata);
    if (!branch.failure.empty()) header += "# INCOMPLETE: the branch ended in a failure: " + branch.failure + "\n";
    write_output(inv, dir / "equilibria.csv", points_csv(header, problem, branch, eq.options.nroots));
    write_output(inv, dir / "equilibrium_bifurcations.csv", bifurcations_csv(header, branch));
    json file = j;
    file["metadata"] = metadata_json(metadata);
    write_output(inv, dir / "continue.json", file.dump(2) + "\n");
  }
  if (!branch.failure.empty()) {
    inv.err << "delayspec continue: numerical failure: " << branch.failure
            << (inv.out_dir ? "; the branch so far is in " + *inv.out_dir : std::string()) << "\n";
    return 3;
  }
  if (inv.json)
    inv.out << j.dump(2) << "\n";
  else
    print_branch(inv.out, problem, settings.key, o, branch, seconds);
  return 0;
}

}  // namespace delayspec::cli
