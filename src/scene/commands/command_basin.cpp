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

// What the command reads and checks before any work; the keys are read in this order (--help lists them so).
struct BasinSettings {
  ParameterAxis x, y;
  long transient = 0, max_period = 0;
  double tolerance = 0;
  int threads = 1;
  Problem problem;
  long count = 0;  // the grid's points, x fastest
};

// Reads and checks the axes, the classification's keys and the problem.
BasinSettings read_basin_settings(Config& config) {
  BasinSettings s;
  s.x = read_parameter_axis(config, "basin", "x", "x0", -3, 3, 15);
  s.y = read_parameter_axis(config, "basin", "y", "v0", -3, 3, 15);
  if (s.x.name == s.y.name) throw BadInput("`basin_x = basin_y = " + s.x.name + "`: the two axes must differ");
  s.transient = config.get_int_in_range("basin_transient", 400, 0, 100'000'000);
  s.max_period = config.get_int_in_range("basin_max_period", 8, 1, 10000);
  s.tolerance = config.get_double("basin_tolerance", 1e-6);
  require_positive("basin_tolerance", s.tolerance);
  s.threads = read_threads(config);
  s.problem = read_problem(config, 50);
  require_model_parameter(config, "basin_x", s.x.name, s.problem.model_name);
  require_model_parameter(config, "basin_y", s.y.name, s.problem.model_name);
  config.check_all_used();
  s.count = grid_point_count(s.x, s.y, "basin");
  return s;
}

// Every point's result by index; a point with a failure has no classification.
struct BasinPoints {
  explicit BasinPoints(long count) : result(static_cast<size_t>(count)), failure(static_cast<size_t>(count)) {}
  std::vector<Classification> result;
  std::vector<std::string> failure;
};

// A point's record: its row of the result, its line in --out DIR's log (point_files.hpp), and its
// message to the lead under mpirun (distributed_points.hpp).
nlohmann::json basin_record(const BasinSettings& s, const BasinPoints& pts, long i) {
  nlohmann::json row = {{"index", i}, {"x", s.x.value(i % s.x.points)}, {"y", s.y.value(i / s.x.points)}};
  if (pts.failure[i].empty()) {
    row["period"] = pts.result[i].period;
    row["max_section_x"] = pts.result[i].max_section_x;
  } else {
    row["period"] = nullptr;
    row["failure"] = pts.failure[i];
  }
  return row;
}

// Keeps the result of a record (a resumed point, or a worker's).
bool take_basin_record(BasinPoints& pts, long i, const nlohmann::json& row) {
  if (row.contains("failure")) {
    pts.failure[i] = row.at("failure").get<std::string>();
  } else {
    pts.result[i].period = row.at("period").get<int>();
    pts.result[i].max_section_x = row.at("max_section_x").is_number() ? row["max_section_x"].get<double>() : NAN;
  }
  return true;
}

// Simulates point i past the transient and classifies its attractor by the section's period.
void compute_basin_point(const Config& config, const BasinSettings& s, BasinPoints& pts, long i) {
  Config point = config;
  point.set(s.x.name, format_number(s.x.value(i % s.x.points)), "basin");
  point.set(s.y.name, format_number(s.y.value(i / s.x.points)), "basin");
  const Problem p = read_problem(point, 50);
  try {
    // Section sequence U_0 .. U_{2 P}: enough to test every p <= P on P + 1 pairs.
    const std::vector<Eigen::VectorXd> section =
        p.analyses->section_sequence(p.map_settings(), s.transient, 2 * s.max_period + 1);
    const int d = p.state_dimension();
    Classification c;
    c.max_section_x = -INFINITY;
    bool finite = true;
    for (const auto& S : section) {
      finite = finite && S.allFinite();
      if (finite) c.max_section_x = std::max(c.max_section_x, S[S.size() - d]);  // u_0's first component
    }
    if (finite) {
      c.period = section_period(section, s.max_period, s.tolerance);
      pts.result[i] = c;
    } else {
      pts.failure[i] = "trajectory not finite";
    }
  } catch (const NumericalFailure& e) {
    pts.failure[i] = e.what();  // reported with the point, not fatal to the basin
  }
}

// The rows of the result, the points by period and the failed ones.
struct BasinTally {
  std::map<int, long> counts;
  long failed = 0;
  nlohmann::json rows = nlohmann::json::array();
};

// Counts the points by period and collects the rows (without their index).
BasinTally tally_basin(const BasinSettings& s, const BasinPoints& pts) {
  BasinTally t;
  for (long i = 0; i < s.count; ++i) {
    nlohmann::json row = basin_record(s, pts, i);
    row.erase("index");
    if (pts.failure[i].empty()) ++t.counts[pts.result[i].period];
    else ++t.failed;
    t.rows.push_back(row);
  }
  return t;
}

// --out DIR: basin.csv in gnuplot's grid format (a blank line ends each y block).
void write_basin_csv(const Invocation& inv, const Config& config, const BasinSettings& s, const BasinPoints& pts,
                     const nlohmann::json& json, double seconds) {
  OutputFile csv(inv, std::filesystem::path(*inv.out_dir) / "basin.csv");
  OutputMetadata metadata = make_metadata("basin", inv.scene, config, json, seconds);
  name_model(metadata, s.problem.model_label, s.problem.state_names);
  csv.stream() << metadata_comment_lines(metadata);
  csv.stream() << s.x.name << "," << s.y.name << ",period,max_section_x\n";
  csv.stream().precision(12);
  for (long i = 0; i < s.count; ++i) {
    if (i > 0 && i % s.x.points == 0) csv.stream() << "\n";
    csv.stream() << s.x.value(i % s.x.points) << "," << s.y.value(i / s.x.points) << ",";
    if (pts.failure[i].empty()) csv.stream() << pts.result[i].period << "," << pts.result[i].max_section_x << "\n";
    else csv.stream() << "nan,nan\n";
  }
  csv.commit();
}

// The text summary: the grid, the points by period, the failed ones, the time.
void print_basin(std::ostream& out, const BasinSettings& s, const BasinTally& t, double seconds) {
  const ParameterAxis &x = s.x, &y = s.y;
  out << "delayspec basin: model " << s.problem.model_label << ", N = " << s.problem.N << ", " << x.name << " in ["
      << x.min << ", " << x.max << "] x " << y.name << " in [" << y.min << ", " << y.max << "], " << s.count
      << " points, transient " << s.transient << " periods\n";
  for (const auto& [period, n] : t.counts)
    out << "  " << (period == 0 ? "no period <= " + std::to_string(s.max_period) : "period " + std::to_string(period))
        << ": " << n << " points\n";
  if (t.failed) out << "  failed: " << t.failed << " points\n";
  out << "time: " << seconds << " s\n";
}

}  // namespace

int command_basin(Config& config, const Invocation& inv) {
  const auto start = std::chrono::steady_clock::now();
  const BasinSettings s = read_basin_settings(config);
  BasinPoints pts(s.count);
  PointLoop loop{.command = "basin", .count = s.count, .threads = s.threads, .per_point_keys = {s.x.name, s.y.name}};
  loop.record = [&](long i) { return basin_record(s, pts, i); };
  loop.take = [&](long i, const nlohmann::json& row) { return take_basin_record(pts, i, row); };
  loop.compute = [&](long i) { compute_basin_point(config, s, pts, i); };
  run_point_loop(loop, config, inv);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const BasinTally t = tally_basin(s, pts);
  nlohmann::json count_json = nlohmann::json::object();
  for (const auto& [period, n] : t.counts) count_json[std::to_string(period)] = n;
  nlohmann::json json = grid_json(s.problem, s.x, s.y);
  json.update(nlohmann::json{{"transient", s.transient},
                             {"max_period", s.max_period},
                             {"tolerance", s.tolerance},
                             {"counts", count_json},
                             {"failed_points", t.failed},
                             {"threads", s.threads},
                             {"seconds", seconds},
                             {"rows", t.rows}});
  if (inv.out_dir) write_basin_csv(inv, config, s, pts, json, seconds);
  if (inv.json) inv.out << json.dump(2) << "\n";
  else print_basin(inv.out, s, t, seconds);
  return report_failed_points(inv.err, "basin", t.rows);
}

}  // namespace delayspec::cli
