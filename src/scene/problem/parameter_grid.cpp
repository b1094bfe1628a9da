#include "scene/problem/parameter_grid.hpp"

#include <sched.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <thread>
#include <vector>

#include "delayspec/errors.hpp"

namespace delayspec::cli {

void require_finite_width(const std::string& keys, double from, double to) {
  if (!std::isfinite(to - from))
    throw BadInput(keys + ": the width of the range overflows (" + format_number(to) + " - " + format_number(from) +
                   " is not a finite number); give a range narrower than 1.7e308");
}

ParameterAxis read_parameter_axis(Config& config, const std::string& prefix, const std::string& axis,
                                  const std::string& default_name, double default_min, double default_max,
                                  long default_points) {
  ParameterAxis a;
  a.name = config.get_string(prefix + "_" + axis, default_name);
  const std::string range_key = prefix + "_" + axis + "_range";
  const std::string range = config.get_string(range_key, format_number(default_min) + "," + format_number(default_max));
  std::vector<double> values;
  std::stringstream ss(range);
  std::string item;
  while (std::getline(ss, item, ',')) {
    Config one;  // the typed number parser, so that errors name the key
    one.set(range_key, item, range_key);
    try {
      values.push_back(one.get_double(range_key, 0));
    } catch (const BadInput&) {
      throw BadInput("`" + range_key + " = " + range + "`: `" + item + "` is not a finite number");
    }
  }
  if (values.size() != 2 || !(values[0] < values[1]))
    throw BadInput("`" + range_key + " = " + range + "`: must be two numbers [min, max] with min < max");
  require_finite_width("`" + range_key + " = " + range + "`", values[0], values[1]);
  a.min = values[0];
  a.max = values[1];
  const std::string points_key = prefix + "_" + axis + "_points";
  a.points = config.get_int_in_range(points_key, default_points, 2, 100000);
  return a;
}

long grid_point_count(const ParameterAxis& x, const ParameterAxis& y, const std::string& prefix) {
  constexpr long kMaxPoints = 10'000'000;
  if (x.points > kMaxPoints / y.points)
    throw BadInput("`" + prefix + "_x_points = " + std::to_string(x.points) + "`, `" + prefix +
                   "_y_points = " + std::to_string(y.points) + "`: at most 1e7 grid points in all");
  return x.points * y.points;
}

void require_model_parameter(const Config& config, const std::string& key, const std::string& name,
                             const std::string& model_name) {
  if (!config.used_keys().count(name) || name == "N" || name == "model" || name == "orbit_period")
    throw BadInput("`" + key + " = " + name + "`: not a numeric parameter of model " + model_name);
}

int read_threads(Config& config) {
  // 0 = all cores this process may run on: its CPU affinity mask, which mpirun and Slurm set
  // per rank (a rank bound to one core gets one thread, not one per core of the node).
  long hardware = std::max(1u, std::thread::hardware_concurrency());
  cpu_set_t allowed;
  if (sched_getaffinity(0, sizeof allowed, &allowed) == 0) hardware = std::max(1, CPU_COUNT(&allowed));
  const long threads = config.get_int_in_range("threads", 0, 0, 4096);
  return static_cast<int>(threads == 0 ? hardware : threads);
}

int report_failed_points(std::ostream& err, const std::string& command, const nlohmann::json& rows) {
  const nlohmann::json* first = nullptr;
  long failed = 0;
  for (const auto& row : rows)
    if (row.contains("failure")) {
      if (!first) first = &row;
      ++failed;
    }
  if (failed == 0) return 0;
  err << "delayspec " << command << ": numerical failure at " << failed << " of " << rows.size()
      << " point(s), first: (" << format_number((*first)["x"].get<double>()) << ", "
      << format_number((*first)["y"].get<double>()) << "): " << (*first)["failure"].get<std::string>() << "\n";
  return 3;
}

nlohmann::json grid_json(const Problem& problem, const ParameterAxis& x, const ParameterAxis& y) {
  return {{"model", problem.model_name},
          {"N", problem.N},
          {"events", to_string(problem.events)},
          {"jacobian", to_string(problem.jacobian)},
          {"x", x.name},
          {"y", y.name},
          {"x_range", {x.min, x.max}},
          {"y_range", {y.min, y.max}},
          {"x_points", x.points},
          {"y_points", y.points}};
}

}  // namespace delayspec::cli
