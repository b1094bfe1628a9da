#include "scene/problem/equilibrium_settings.hpp"

#include <string>

#include "delayspec/errors.hpp"
#include "scene/problem/floquet_settings.hpp"

namespace delayspec::cli {

EquilibriumSettings read_equilibrium_settings(Config& config, const Problem& problem) {
  EquilibriumSettings s;
  s.options.N = problem.N;
  // 1000 roots is far beyond any use: each is a Newton iteration on a d x d complex determinant.
  s.options.nroots = static_cast<int>(config.get_int_in_range("nroots", s.options.nroots, 1, 1000));
  const std::vector<double> guess = config.get_double_list("equilibrium_guess", "history");
  const int d = problem.state_dimension();
  if (!guess.empty() && static_cast<int>(guess.size()) != d) {
    std::string names;
    for (const std::string& name : problem.state_names) names += (names.empty() ? "" : ", ") + name;
    throw BadInput("`equilibrium_guess`: " + std::to_string(guess.size()) + " numbers given; the state has " +
                   std::to_string(d) + " (" + names + ")");
  }
  s.guess = Eigen::Map<const Eigen::VectorXd>(guess.data(), static_cast<long>(guess.size()));
  // Newton on the state and on each root stops at |step| <= tolerance (1 + |x|); above 1e-3 the
  // roots would not be "refined" in any useful sense.
  s.options.tolerance = config.get_double("equilibrium_tolerance", s.options.tolerance);
  if (!(s.options.tolerance > 0 && s.options.tolerance <= 1e-3))
    throw BadInput("`equilibrium_tolerance = " + format_number(s.options.tolerance) + "`: must be in (0, 1e-3]");
  s.options.eigensolver = read_eigensolver_options(config);
  return s;
}

void require_autonomous(const Problem& problem) {
  require_autonomous_model(problem.analyses->is_autonomous(), problem.model_name, problem.model.has_value());
}

}  // namespace delayspec::cli
