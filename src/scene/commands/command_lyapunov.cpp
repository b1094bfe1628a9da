// delayspec lyapunov: the leading Lyapunov exponents of the attractor reached from the model's
// constant initial history (CLI contract; lyapunov.hpp for the method).
#include <chrono>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "scene/commands/commands.hpp"
#include "scene/problem/lyapunov_settings.hpp"
#include "scene/output/output.hpp"
#include "scene/problem/problem.hpp"
#include "scene/output/progress.hpp"

namespace delayspec::cli {

int command_lyapunov(Config& config, const Invocation& inv) {
  const auto start = std::chrono::steady_clock::now();
  Problem problem = read_problem(config, 100);
  LyapunovOptions options = read_lyapunov_options(config, 2);
  config.check_all_used();
  const long n = problem.dimension();
  validate_lyapunov_options(options, n);

  Progress progress(inv.err, "lyapunov", options.transient + options.periods, inv.quiet);
  options.progress = [&progress](long, long) { progress.add(); };
  const LyapunovResult r = run_lyapunov(problem, options);
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  if (inv.json) {
    nlohmann::json j = lyapunov_json(r);
    j["model"] = problem.model_name;
    j["N"] = problem.N;
    j["dimension"] = n;
    j["periods"] = r.periods;
    j["transient"] = r.transient;
    j["seconds"] = seconds;
    j["qr_seconds"] = r.qr_seconds;
    j["qr_every"] = r.qr_every;
    j["batches"] = r.batches;
    j["seed"] = options.seed;
    j["steps"] = r.steps;
    j["h"] = problem.grid().h;
    j["events"] = to_string(problem.events);
    j["grid"] = grid_json(problem.grid());
    j["jacobian"] = to_string(problem.jacobian);
    inv.out << j.dump(2) << "\n";
  } else {
    inv.out << "delayspec lyapunov: model " << problem.model_label << ", " << problem.grid().describe() << ", n = " << n
            << "\n";
    inv.out << r.per_period.size() << " leading Lyapunov exponents after a transient of " << r.transient
            << " periods, averaged over " << r.periods << " periods (period = " << r.map_time
            << " time units, QR every " << r.qr_every << "; error = sqrt(SE^2 + F^2), SE the standard error of "
            << r.batches << " batch means, F the range of the detrended cumulative sum / periods):\n";
    char line[200];
    std::snprintf(line, sizeof line, "  %3s  %24s  %24s\n", "#", "per period", "per unit time");
    inv.out << line;
    for (size_t i = 0; i < r.per_period.size(); ++i) {
      std::snprintf(line, sizeof line, "  %3zu  %+.6e +- %.1e  %+.6e +- %.1e\n", i + 1, r.per_period[i],
                    r.error_per_period[i], r.per_time[i], r.error_per_time[i]);
      inv.out << line;
    }
    inv.out << "time: " << seconds << " s (QR " << r.qr_seconds << " s)\n";
  }
  return 0;
}

}  // namespace delayspec::cli
