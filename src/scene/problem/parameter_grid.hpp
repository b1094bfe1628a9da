#pragma once
// The keys of a two-parameter grid (chart, basin): PREFIX_x / PREFIX_y name the parameters,
// PREFIX_x_range / PREFIX_y_range are [min, max], PREFIX_x_points / PREFIX_y_points (>= 2) the
// number of equally spaced values including both ends; and `threads` for running the points.
#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include "scene/keys/config.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

struct ParameterAxis {
  std::string name;
  double min = 0, max = 0;
  long points = 0;
  // The i-th value, i = 0..points-1: min + (max - min) i / (points - 1).
  double value(long i) const { return min + (max - min) * static_cast<double>(i) / static_cast<double>(points - 1); }
};

// A range of equally spaced values from + (to - from) i / (n - 1) (sweep, chart, basin, the
// default steps of continue) needs a finite width to - from: from = -1e308, to = 1e308 gives
// to - from = inf and every value nan. BadInput naming `keys` (e.g. "`sweep_from = -1e308`,
// `sweep_to = 1e308`") otherwise. from and to are finite (their readers check).
void require_finite_width(const std::string& keys, double from, double to);

// Reads PREFIX_AXIS, PREFIX_AXIS_range, PREFIX_AXIS_points (AXIS = "x" or "y"); BadInput naming
// the key and value when the range is not two finite numbers min < max with a finite width, or
// points is not in [2, 100000].
ParameterAxis read_parameter_axis(Config& config, const std::string& prefix, const std::string& axis,
                                  const std::string& default_name, double default_min, double default_max,
                                  long default_points);

// The number of grid points, x.points * y.points; BadInput naming both keys when it exceeds 1e7
// (every point keeps its result in memory until the table is written).
long grid_point_count(const ParameterAxis& x, const ParameterAxis& y, const std::string& prefix);

// After read_problem(config): BadInput unless the axis names a numeric model parameter (a key
// read_problem read, other than model and N).
void require_model_parameter(const Config& config, const std::string& key, const std::string& name,
                             const std::string& model_name);

// The `threads` key (as `sweep`): 0 (the default) = the cores this process may run on (its CPU
// affinity: all hardware threads, or those mpirun / Slurm gave the rank); BadInput unless 0..4096.
int read_threads(Config& config);

// The exit status of a grid command whose `rows` ([{"x", "y", ..., "failure"?}]) are written:
// 0 when no row has a "failure"; else 3 with one line on `err` (how many points failed, the first
// one and its reason), as sweep does for its failed points.
int report_failed_points(std::ostream& err, const std::string& command, const nlohmann::json& rows);

// The JSON fields a grid command shares (chart, basin): model, N, events, jacobian and the two
// axes (x, y, x_range, y_range, x_points, y_points). The command adds its own.
nlohmann::json grid_json(const Problem& problem, const ParameterAxis& x, const ParameterAxis& y);

}  // namespace delayspec::cli
