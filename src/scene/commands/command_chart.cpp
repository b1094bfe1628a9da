// delayspec chart: a stability chart, the spectral radius |mu_1| of the monodromy over a grid of
// two model parameters (default: the delayed Mathieu equation's (delta, b) plane, the classic
// chart of Insperger & Stepan). Points run in parallel (`threads`), under mpirun over the ranks
// too; with --out DIR each finished point is kept in DIR/chart_points/ and --resume completes an
// interrupted chart (point_loop.hpp).
//
// Keys: chart_x, chart_y (parameter names, default delta and b), chart_x_range, chart_y_range
// (two numbers [min, max]), chart_x_points, chart_y_points (>= 2), threads; plus the problem,
// orbit and eigen-solver keys (nev defaults to 1 here: only |mu_1| is wanted); error_bars (on:
// each point's |mu_1| with its error bar and verdict, floquet's rule, about 1.4x the time; off
// by default here, see below).
// Output: JSON {"x", "y", "x_values", "y_values", "rows": [{"x", "y", "spectral_radius",
// "error_estimate", "verdict"}], "stable_points", "undecided_points", ...};
// with --out DIR also DIR/chart.csv: x,y,spectral_radius[,error_estimate,undecided], one block per y value separated by a
// blank line (gnuplot's grid format), metadata as "#" comment lines first. A point that fails
// numerically (e.g. no periodic orbit) is recorded (spectral_radius null, its "failure"; nan in
// the CSV), the others still run, and the command exits 3 after writing everything, as sweep does.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <thread>

#include "scene/output/output_directory.hpp"
#include "scene/commands/commands.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/stroboscopic_map.hpp"
#include "scene/problem/floquet_settings.hpp"
#include "scene/problem/level_runner.hpp"
#include "scene/output/metadata.hpp"
#include "scene/output/output.hpp"
#include "scene/problem/orbit_settings.hpp"
#include "scene/problem/parameter_grid.hpp"
#include "scene/points/point_loop.hpp"
#include "scene/problem/problem.hpp"

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
  // Each point's |mu_1| with its error bar and verdict (floquet's rule: error_bars.hpp). Off by
  // default here, for now: at the chart's N = 40 the levels N/8 = 5 and N/4 = 10 are too coarse
  // (Mathieu's default plane: 66 of 100 points undecided; at N = 200, 1; at N = 400, none), and
  // a default N that gives verdicts changes the charts the docs show (issue 32 stays open on it).
  const bool with_error_bars = config.get_choice("error_bars", "off", {"on", "off"}) == "on";
  require_model_parameter(config, "chart_x", x.name, problem.model_name);
  require_model_parameter(config, "chart_y", y.name, problem.model_name);
  config.check_all_used();

  const long count = grid_point_count(x, y, "chart");
  std::vector<double> radius(static_cast<size_t>(count), NAN);
  std::vector<std::string> failure(static_cast<size_t>(count));
  std::vector<double> bar(static_cast<size_t>(count), NAN);  // error_estimate of |mu_1| (inf: none)
  std::vector<std::string> verdict(static_cast<size_t>(count));
  // A point's record: its row of the result, its file in --out DIR (point_files.hpp), and its
  // message to the lead under mpirun (distributed_points.hpp).
  auto record = [&](long i) {
    nlohmann::json row = {{"index", i}, {"x", x.value(i % x.points)}, {"y", y.value(i / x.points)}};
    row["spectral_radius"] = failure[i].empty() ? nlohmann::json(radius[i]) : nlohmann::json(nullptr);
    if (!failure[i].empty()) row["failure"] = failure[i];
    if (with_error_bars && failure[i].empty()) {
      row["error_estimate"] = number_or_null(bar[i]);
      row["verdict"] = verdict[i];
    }
    return row;
  };
  auto take_record = [&](long i, const nlohmann::json& row) {
    if (row.contains("failure")) failure[i] = row.at("failure").get<std::string>();
    else radius[i] = row.at("spectral_radius").is_number() ? row["spectral_radius"].get<double>() : NAN;
    if (with_error_bars && !row.contains("failure")) {
      if (!row.contains("verdict")) return false;  // a point file of a run without error bars: recompute
      verdict[i] = row.at("verdict").get<std::string>();
      bar[i] = row.at("error_estimate").is_number() ? row["error_estimate"].get<double>() : INFINITY;
    }
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
      const FloquetResult result = floquet_multipliers(*at_orbit.monodromy, options);
      radius[i] = std::abs(result.multipliers.at(0));
      if (with_error_bars) {
        double seconds = 0;
        const ErrorBars bars =
            floquet_error_bars(p, orbit_settings, options, level_result(result, p.dimension(), p.grid().K), {}, seconds);
        verdict[i] = to_string(bars.verdict);
        bar[i] = bars.bars.at(0).error_estimate;
      }
    } catch (const NumericalFailure& e) {
      failure[i] = e.what();  // e.g. no periodic orbit at this point: reported, not fatal
    }
  };
  run_point_loop(loop, config, inv);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Stable: with error bars, the points whose verdict is stable (the bar inside the circle);
  // without, |mu_1| < 1 as computed.
  long stable = 0, undecided = 0, failed = 0;
  nlohmann::json rows = nlohmann::json::array();
  for (long i = 0; i < count; ++i) {
    nlohmann::json row = record(i);
    row.erase("index");
    if (!failure[i].empty()) ++failed;
    else if (!with_error_bars) stable += radius[i] < 1;
    else stable += verdict[i] == "stable", undecided += verdict[i] == "undecided";
    rows.push_back(row);
  }
  nlohmann::json json = grid_json(problem, x, y);
  if (with_error_bars) json["undecided_points"] = undecided;
  json.update(nlohmann::json{{"points", count},
                             {"stable_points", stable},
                             {"failed_points", failed},
                             {"threads", threads},
                             {"seconds", seconds},
                             {"rows", rows}});

  if (inv.out_dir) {
    OutputFile csv(inv, std::filesystem::path(*inv.out_dir) / "chart.csv");
    csv.stream() << metadata_comment_lines(make_metadata("chart", inv.scene, config, json, seconds));
    csv.stream() << x.name << "," << y.name << ",spectral_radius" << (with_error_bars ? ",error_estimate,undecided" : "")
                 << "\n";
    csv.stream().precision(12);
    for (long i = 0; i < count; ++i) {
      if (i > 0 && i % x.points == 0) csv.stream() << "\n";  // a blank line ends each y block
      csv.stream() << x.value(i % x.points) << "," << y.value(i / x.points) << ",";
      if (failure[i].empty()) csv.stream() << radius[i];
      else csv.stream() << "nan";
      // undecided: 1 where the circle is within the bar, 0 where a verdict was reached (nan: failed)
      if (with_error_bars)
        csv.stream() << "," << (failure[i].empty() && std::isfinite(bar[i]) ? bar[i] : NAN) << ","  // nan: no bar
                     << (failure[i].empty() ? (verdict[i] == "undecided" ? "1" : "0") : "nan");
      csv.stream() << "\n";
    }
    csv.commit();
  }
  if (inv.json) {
    inv.out << json.dump(2) << "\n";
  } else {
    inv.out << "delayspec chart: model " << problem.model_name << ", N = " << problem.N << ", " << x.name << " in ["
            << x.min << ", " << x.max << "] x " << y.name << " in [" << y.min << ", " << y.max << "], " << count
            << " points on " << threads << " threads\n";
    if (with_error_bars)
      inv.out << "stable (|mu_1| + its error bar < 1): " << stable << " of " << count << " points, undecided "
              << undecided;
    else
      inv.out << "stable (|mu_1| < 1): " << stable << " of " << count << " points";
    if (failed) inv.out << "; " << failed << " points failed (see --json)";
    inv.out << "\ntime: " << seconds << " s\n";
    if (inv.out_dir) inv.out << "wrote " << (std::filesystem::path(*inv.out_dir) / "chart.csv").string() << "\n";
  }
  return report_failed_points(inv.err, "chart", rows);
}

}  // namespace delayspec::cli
