#include "scene/problem/continue_settings.hpp"

#include <cmath>

#include "delayspec/errors.hpp"
#include "scene/problem/level_runner.hpp"
#include "scene/problem/parameter_grid.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

ContinueSettings read_continue_settings(Config& config) {
  ContinueSettings s;
  if (!config.has("continue_key"))
    throw BadInput("missing key `continue_key` (the model parameter to continue, e.g. k)");
  s.key = config.get_string("continue_key", "");
  ContinuationOptions& o = s.options;
  o.from = config.require_double("continue_from");
  o.to = config.require_double("continue_to");
  if (o.from == o.to) throw BadInput("`continue_from = continue_to = " + format_number(o.from) + "`: an empty range");
  require_finite_width("`continue_from = " + format_number(o.from) + "`, `continue_to = " + format_number(o.to) + "`",
                       o.from, o.to);
  // 0: the defaults relative to the range (continuation.hpp)
  o.step = config.get_double("continue_step", 0);
  o.step_min = config.get_double("continue_step_min", 0);
  o.step_max = config.get_double("continue_step_max", 0);
  for (const auto& [name, value] : {std::pair{"continue_step", o.step}, std::pair{"continue_step_min", o.step_min},
                                    std::pair{"continue_step_max", o.step_max}})
    if (!(value >= 0) || !std::isfinite(value))
      throw BadInput("`" + std::string(name) + " = " + format_number(value) + "`: must be > 0 (or 0 for the default)");
  // The library's defaults for 0 (continuation.hpp), so that a step_min above step_max is named by the keys
  const double range = std::abs(o.to - o.from);
  const double step_min = o.step_min > 0 ? o.step_min : 1e-6 * range,
               step_max = o.step_max > 0 ? o.step_max : range / 10;
  if (step_min > step_max)
    throw BadInput("`continue_step_min = " + format_number(step_min) +
                   "` exceeds `continue_step_max = " + format_number(step_max) + "`");
  o.max_points = static_cast<int>(config.get_int_in_range("continue_max_points", 500, 2, 10'000'000));
  o.tolerance = config.get_double("continue_tolerance", 0);
  if (!(o.tolerance >= 0) || !std::isfinite(o.tolerance))
    throw BadInput("`continue_tolerance = " + format_number(o.tolerance) +
                   "`: must be > 0 (or 0 for 1e-10 |to - from|)");
  s.Ns = read_levels(config, "continue_Ns");
  // With error bars the locations are extrapolated, and a location known only to the library's
  // default 1e-10 |to - from| puts a floor under every bar (about twice the tolerance: the
  // Richardson weights) far above the extrapolation's own error: on x' = -x + b x(t - tau) over
  // N = 100 .. 1600 a bar of 2e-10 for an error of 4e-13. Each location is then narrowed on
  // towards 1e-13 |to - from| while that works (BranchRange::refine_tolerance: the regula falsi
  // converges superlinearly where the test function is smooth, no more evaluations there; near a
  // grazing, where the corrector may fail on one side, it stops), and the bracket it reaches is
  // carried into the bar (extrapolate_bifurcations). A tolerance the user gives is kept as given.
  if (o.tolerance == 0 && s.Ns.size() >= 2) o.refine_tolerance = 1e-13 * range;
  s.switch_period_doubling = config.get_enum("continue_switch", false, {{"false", false}, {"true", true}});
  const std::string solver = config.get_choice("continue_solver", "auto", {"auto", "krylov", "lu"});
  o.solver = solver == "krylov" ? ContinuationSolver::krylov
             : solver == "lu"   ? ContinuationSolver::lu
                                : ContinuationSolver::automatic;
  return s;
}

}  // namespace delayspec::cli
