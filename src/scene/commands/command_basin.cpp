// delayspec basin: basins of attraction over a grid of constant initial histories (paper
// Fig. 6.1: (x0, v0) at k = 0). Each point is simulated for `basin_transient` stroboscopic
// maps, then its attractor is classified by period detection on the section: the smallest
// p <= basin_max_period with |U_{j+p} - U_j|_inf <= basin_tolerance (1 + |U_j|_inf) for
// j = 0..basin_max_period (U_j the history after transient + j maps); period 0 when there is
// none (chaotic, quasi-periodic, a longer period, or not yet settled). Each point also reports
// max x over the section points (telling apart attractors of equal period) and the impacts.
//
// Points run in parallel (`threads`), under mpirun over the ranks too; with --out DIR each
// finished point is kept in DIR/basin_points/ and --resume completes an interrupted basin
// (point_loop.hpp).
//
// Keys: basin_x, basin_y (default x0, v0), basin_x_range, basin_y_range ([min, max]),
// basin_x_points, basin_y_points (>= 2), basin_transient (default 400), basin_max_period
// (default 8), basin_tolerance (default 1e-6), threads; plus the problem keys.
// Output: JSON {"x", "y", "rows": [{"x", "y", "period", "max_section_x"}], "counts": {period: n}};
// with --out DIR also DIR/basin.csv: x,y,period,max_section_x in gnuplot's grid format.
// A point whose trajectory fails (not finite, or a numerical failure of the stepper) is recorded
// (period null, its "failure"; nan in the CSV), the others still run, and the command exits 3
// after writing everything, as sweep does.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "scene/output/output_directory.hpp"
#include "scene/commands/commands.hpp"
#include "delayspec/stroboscopic_map.hpp"
#include "scene/output/metadata.hpp"
#include "scene/problem/parameter_grid.hpp"
#include "scene/points/point_loop.hpp"
#include "scene/problem/problem.hpp"
#include "scene/problem/section_period.hpp"

namespace delayspec::cli {

namespace {

struct Classification {
  int period = 0;  // 0: no period <= max_period found
  double max_section_x = NAN;
};

}  // namespace

int command_basin(Config& config, const Invocation& inv) {
  const auto start = std::chrono::steady_clock::now();
  const ParameterAxis x = read_parameter_axis(config, "basin", "x", "x0", -3, 3, 15);
  const ParameterAxis y = read_parameter_axis(config, "basin", "y", "v0", -3, 3, 15);
  if (x.name == y.name) throw BadInput("`basin_x = basin_y = " + x.name + "`: the two axes must differ");
  const long transient = config.get_int_in_range("basin_transient", 400, 0, 100'000'000);
  const long max_period = config.get_int_in_range("basin_max_period", 8, 1, 10000);
  const double tolerance = config.get_double("basin_tolerance", 1e-6);
  require_positive("basin_tolerance", tolerance);
  const int threads = read_threads(config);
  const Problem problem = read_problem(config, 50);
  require_model_parameter(config, "basin_x", x.name, problem.model_name);
  require_model_parameter(config, "basin_y", y.name, problem.model_name);
  config.check_all_used();

  const long count = grid_point_count(x, y, "basin");
  std::vector<Classification> result(static_cast<size_t>(count));
  std::vector<std::string> failure(static_cast<size_t>(count));
  // A point's record: its row of the result, its file in --out DIR (point_files.hpp), and its
  // message to the lead under mpirun (distributed_points.hpp).
  auto record = [&](long i) {
    nlohmann::json row = {{"index", i}, {"x", x.value(i % x.points)}, {"y", y.value(i / x.points)}};
    if (failure[i].empty()) {
      row["period"] = result[i].period;
      row["max_section_x"] = result[i].max_section_x;
    } else {
      row["period"] = nullptr;
      row["failure"] = failure[i];
    }
    return row;
  };
  auto take_record = [&](long i, const nlohmann::json& row) {
    if (row.contains("failure")) {
      failure[i] = row.at("failure").get<std::string>();
    } else {
      result[i].period = row.at("period").get<int>();
      result[i].max_section_x = row.at("max_section_x").is_number() ? row["max_section_x"].get<double>() : NAN;
    }
    return true;
  };
  PointLoop loop{.command = "basin", .count = count, .threads = threads, .per_point_keys = {x.name, y.name}};
  loop.record = record;
  loop.take = take_record;
  loop.compute = [&](long i) {
    Config point = config;
    point.set(x.name, format_number(x.value(i % x.points)), "basin");
    point.set(y.name, format_number(y.value(i / x.points)), "basin");
    const Problem p = read_problem(point, 50);
    try {
      // Section sequence U_0 .. U_{2 P}: enough to test every p <= P on P + 1 pairs.
      const std::vector<Eigen::VectorXd> section =
          p.analyses->section_sequence(p.map_settings(), transient, 2 * max_period + 1);
      const int d = p.state_dimension();
      Classification c;
      c.max_section_x = -INFINITY;
      bool finite = true;
      for (const auto& S : section) {
        finite = finite && S.allFinite();
        if (finite) c.max_section_x = std::max(c.max_section_x, S[S.size() - d]);  // u_0's first component
      }
      if (finite) {
        c.period = section_period(section, max_period, tolerance);
        result[i] = c;
      } else {
        failure[i] = "trajectory not finite";
      }
    } catch (const NumericalFailure& e) {
      failure[i] = e.what();  // reported with the point, not fatal to the basin
    }
  };
  run_point_loop(loop, config, inv);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::map<int, long> counts;
  long failed = 0;
  nlohmann::json rows = nlohmann::json::array();
  for (long i = 0; i < count; ++i) {
    nlohmann::json row = record(i);
    row.erase("index");
    if (failure[i].empty()) ++counts[result[i].period];
    else ++failed;
    rows.push_back(row);
  }
  nlohmann::json count_json = nlohmann::json::object();
  for (const auto& [period, n] : counts) count_json[std::to_string(period)] = n;
  nlohmann::json json = grid_json(problem, x, y);
  json.update(nlohmann::json{{"transient", transient},
                             {"max_period", max_period},
                             {"tolerance", tolerance},
                             {"counts", count_json},
                             {"failed_points", failed},
                             {"threads", threads},
                             {"seconds", seconds},
                             {"rows", rows}});
  if (inv.out_dir) {
    OutputFile csv(inv, std::filesystem::path(*inv.out_dir) / "basin.csv");
    csv.stream() << metadata_comment_lines(make_metadata("basin", inv.scene, config, json, seconds));
    csv.stream() << x.name << "," << y.name << ",period,max_section_x\n";
    csv.stream().precision(12);
    for (long i = 0; i < count; ++i) {
      if (i > 0 && i % x.points == 0) csv.stream() << "\n";
      csv.stream() << x.value(i % x.points) << "," << y.value(i / x.points) << ",";
      if (failure[i].empty()) csv.stream() << result[i].period << "," << result[i].max_section_x << "\n";
      else csv.stream() << "nan,nan\n";
    }
    csv.commit();
  }
  if (inv.json) {
    inv.out << json.dump(2) << "\n";
  } else {
    inv.out << "delayspec basin: model " << problem.model_name << ", N = " << problem.N << ", " << x.name << " in ["
            << x.min << ", " << x.max << "] x " << y.name << " in [" << y.min << ", " << y.max << "], " << count
            << " points, transient " << transient << " periods\n";
    for (const auto& [period, n] : counts)
      inv.out << "  "
              << (period == 0 ? "no period <= " + std::to_string(max_period) : "period " + std::to_string(period))
              << ": " << n << " points\n";
    if (failed) inv.out << "  failed: " << failed << " points\n";
    inv.out << "time: " << seconds << " s\n";
  }
  return report_failed_points(inv.err, "basin", rows);
}

}  // namespace delayspec::cli
