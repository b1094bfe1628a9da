// delayspec equilibrium: an equilibrium of an autonomous model and its rightmost characteristic
// roots, refined on the exact characteristic function (equilibrium.hpp for the method).
#include <chrono>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "delayspec/errors.hpp"
#include "scene/commands/commands.hpp"
#include "scene/output/output.hpp"
#include "scene/problem/equilibrium_settings.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

namespace {

nlohmann::json equilibrium_json(const Problem& problem, const EquilibriumResult& r) {
  nlohmann::json j;
  j["model"] = problem.model_name;
  j["N"] = problem.N;
  j["delays"] = problem.analyses->delays();
  j["state_names"] = problem.state_names;
  j["equilibrium"] = std::vector<double>(r.state.data(), r.state.data() + r.state.size());
  j["residual"] = r.residual;
  j["newton_iterations"] = r.newton_iterations;
  j["roots"] = characteristic_roots_json(r.roots);
  j["unstable"] = r.unstable;
  j["critical"] = r.critical;
  j["stable"] = r.stable();
  if (!r.note.empty()) j["note"] = r.note;
  return j;
}

void print_equilibrium(std::ostream& out, const Problem& problem, const EquilibriumResult& r) {
  out << "delayspec equilibrium: model " << problem.model_label << ", N = " << problem.N
      << " steps per the longest delay (the starting roots)\n";
  out << "equilibrium:";
  for (long i = 0; i < r.state.size(); ++i)
    out << (i ? ", " : " ") << problem.state_names[static_cast<size_t>(i)] << " = " << format_number(r.state[i]);
  out << "  (|f|_inf = " << format_number(r.residual) << " after " << r.newton_iterations << " Newton iterations)\n";
  out << "rightmost " << r.roots.size()
      << " characteristic roots, refined on det(lambda I - A - sum_j B_j exp(-lambda tau_j)):\n";
  char line[200];
  std::snprintf(line, sizeof line, "  %3s  %24s  %24s  %9s  %9s  %9s\n", "#", "Re lambda", "Im lambda", "+-",
                "residual", "moved");
  out << line;
  for (size_t i = 0; i < r.roots.size(); ++i) {
    const CharacteristicRoot& c = r.roots[i];
    std::snprintf(line, sizeof line, "  %3zu  %+24.16e  %+24.16e  %9.1e  %9.1e  %9.1e\n", i + 1, c.value.real(),
                  c.value.imag(), c.error_bound, c.residual, std::abs(c.value - c.discretised));
    out << line;
  }
  out << "(+-: bound on the root's error; residual: sigma_min(Delta) / (|lambda| + |A| + sum |B_j|); moved: how far "
         "refinement moved the root from the discretisation's, its error at N)\n";
  if (!r.note.empty()) out << "note: " << r.note << "\n";
  if (r.critical > 0)
    out << "stability: critical, " << r.critical
        << " root(s) on the imaginary axis within their error bound (a fold or Hopf point)\n";
  else if (r.unstable > 0)
    out << "stability: unstable, " << r.unstable << " root(s) with Re lambda > 0"
        << (r.unstable == static_cast<int>(r.roots.size()) ? " (all roots returned: raise nroots for the count)" : "")
        << "\n";
  else
    out << "stability: stable, every root has Re lambda < 0\n";
}

}  // namespace

int command_equilibrium(Config& config, const Invocation& inv) {
  const auto start = std::chrono::steady_clock::now();
  Problem problem = read_problem(config, 100, ModelNeed::autonomous);
  const EquilibriumSettings settings = read_equilibrium_settings(config, problem);
  config.check_all_used();
  require_autonomous(problem);
  const EquilibriumResult r = problem.analyses->equilibrium(settings.guess, settings.options);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (inv.json) {
    nlohmann::json j = equilibrium_json(problem, r);
    j["seconds"] = seconds;
    inv.out << j.dump(2) << "\n";
  } else {
    print_equilibrium(inv.out, problem, r);
    inv.out << "time: " << seconds << " s\n";
  }
  return 0;
}

}  // namespace delayspec::cli
