// delayspec chart: a stability chart, the spectral radius |mu_1| of the monodromy over a grid of
// two model parameters (default: the delayed Mathieu equation's (delta, b) plane, the classic
// chart of Insperger & Stepan). Points run in parallel (`threads`), under mpirun over the ranks
// too; with --out DIR each finished point is kept in DIR/chart_points/ and --resume completes an
// interrupted chart (point_loop.hpp).
//
// Keys: chart_x, chart_y (parameter names, default delta and b), chart_x_range, chart_y_range
// (two numbers [min, max]), chart_x_points, chart_y_points (>= 2), threads; plus the problem,
// orbit and eigen-solver keys (nev defaults to 1 here: only |mu_1| is wanted).
// Output: JSON {"x", "y", "x_values", "y_values", "rows": [{"x", "y", "spectral_radius"}], ...};
// with --out DIR also DIR/chart.csv: x,y,spectral_radius, one block per y value separated by a
// blank line (gnuplot's grid format), metadata as "#" comment lines first. A point that fails
// numerically (e.g. no periodic orbit) is recorded (spectral_radius null, its "failure"; nan in
// the CSV), the others still run, and the command exits 3 after writing everything, as sweep does.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <thread>

#include "atomic_file.hpp"
#include "commands.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/stroboscopic_map.hpp"
#include "floquet_settings.hpp"
#include "metadata.hpp"
#include "orbit_settings.hpp"
#include "parameter_grid.hpp"
#include "point_loop.hpp"
#include "problem.hpp"

namespace delayspec::cli {

int command_chart(Config& config, const Invocation& inv) {
  const auto start = std::chrono::steady_clock::now();
  const ParameterAxis x = read_parameter_axis(config, "chart", "x", "delta", -1, 5, 31);
  const ParameterAxis y = read_parameter_axis(config, "chart", "y", "b", -1.5, 1.5, 31);
  if (x.name == y.name) throw BadInput("`chart_x = chart_y = " + x.name + "`: the two axes must differ");
  const int threads = read_threads(config);
  // Read (and validate) the problem once, as every point will.
  const Problem problem = read_problem(config, 40);
  const OrbitSettings orbit_settings = read_orbit_settings(config);
  read_floquet_options(config, 1);
  require_model_parameter(config, "chart_x", x.name, problem.model_name);
  require_model_parameter(config, "chart_y", y.name, problem.model_name);
  config.check_all_used();

  const long count = grid_point_count(x, y, "chart");
  std::vector<double> radius(static_cast<size_t>(count), NAN);
  std::vector<std::string> failure(static_cast<size_t>(count));
  // A point's record: its row of the result, its file in --out DIR (point_files.hpp), and its
  // message to the lead under mpirun (distributed_points.hpp).
  auto record = [&](long i) {
    nlohmann::json row = {{"index", i}, {"x", x.value(i % x.points)}, {"y", y.value(i / x.points)}};
    row["spectral_radius"] = failure[i].empty() ? nlohmann::json(radius[i]) : nlohmann::json(nullptr);
    if (!failure[i].empty()) row["failure"] = failure[i];
    return row;
  };
  auto take_record = [&](long i, const nlohmann::json& row) {
    if (row.contains("failure")) failure[i] = row.at("failure").get<std::string>();
    else radius[i] = row.at("spectral_radius").is_number() ? row["spectral_radius"].get<double>() : NAN;
    return true;
  };
  PointLoop loop{.command = "chart", .count = count, .threads = threads, .per_point_keys = {x.name, y.name}};
  loop.record = record;
  loop.take = take_record;
  loop.compute = [&](long i) {
    Config point = config;  // each point: its own copy with the two coordinates set
    point.set(x.name, format_number(x.value(i % x.points)), "chart");
    point.set(y.name, format_number(y.value(i / x.points)), "chart");
    const Problem p = read_problem(point, 40);
    const FloquetOptions options = read_floquet_options(point, 1);
    try {
      const LinearisedOrbit at_orbit = p.analyses->linearised_orbit(p.map_settings(), orbit_settings);
      radius[i] = std::abs(floquet_multipliers(*at_orbit.monodromy, options).multipliers.at(0));
    } catch (const NumericalFailure& e) {
      failure[i] = e.what();  // e.g. no periodic orbit at this point: reported, not fatal
    }
  };
  run_point_loop(loop, config, inv);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  long stable = 0, failed = 0;
  nlohmann::json rows = nlohmann::json::array();
  for (long i = 0; i < count; ++i) {
    nlohmann::json row = record(i);
    row.erase("index");
    if (failure[i].empty()) stable += radius[i] < 1;
    else ++failed;
    rows.push_back(row);
  }
  nlohmann::json json = grid_json(problem, x, y);
  json.update(nlohmann::json{{"points", count},
                             {"stable_points", stable},
                             {"failed_points", failed},
                             {"threads", threads},
                             {"seconds", seconds},
                             {"rows", rows}});

  if (inv.out_dir) {
    AtomicFile csv(std::filesystem::path(*inv.out_dir) / "chart.csv");
    csv.stream() << metadata_comment_lines(make_metadata("chart", inv.scene, config, json, seconds));
    csv.stream() << x.name << "," << y.name << ",spectral_radius\n";
    csv.stream().precision(12);
    for (long i = 0; i < count; ++i) {
      if (i > 0 && i % x.points == 0) csv.stream() << "\n";  // a blank line ends each y block
      csv.stream() << x.value(i % x.points) << "," << y.value(i / x.points) << ",";
      if (failure[i].empty()) csv.stream() << radius[i] << "\n";
      else csv.stream() << "nan\n";
    }
    csv.commit();
  }
  if (inv.json) {
    inv.out << json.dump(2) << "\n";
  } else {
    inv.out << "delayspec chart: model " << problem.model_name << ", N = " << problem.N << ", " << x.name << " in ["
            << x.min << ", " << x.max << "] x " << y.name << " in [" << y.min << ", " << y.max << "], " << count
            << " points on " << threads << " threads\n";
    inv.out << "stable (|mu_1| < 1): " << stable << " of " << count << " points";
    if (failed) inv.out << "; " << failed << " points failed (see --json)";
    inv.out << "\ntime: " << seconds << " s\n";
    if (inv.out_dir) inv.out << "wrote " << (std::filesystem::path(*inv.out_dir) / "chart.csv").string() << "\n";
  }
  return report_failed_points(inv.err, "chart", rows);
}

}  // namespace delayspec::cli
