// delayspec chart: a stability chart, the spectral radius |mu_1| of the monodromy over a grid of
// two model parameters (default: the delayed Mathieu equation's (delta, b) plane, the classic
// chart of Insperger & Stepan). Points run in parallel (`threads`), under mpirun over the ranks
// too; with --out DIR each finished point is kept in DIR/chart_points/ and --resume completes an
// interrupted chart (point_loop.hpp).
//
// Keys: chart_x, chart_y (parameter names, default delta and b), chart_x_range, chart_y_range
// (two numbers [min, max]), chart_x_points, chart_y_points (>= 2), threads; plus the problem,
// orbit and eigen-solver keys (nev defaults to 1 here: only |mu_1| is wanted; N to 200); error_bars
// (on, the default: each point's |mu_1| with its error bar and verdict, floquet's rule, about 1.4x
// the time; off: |mu_1| at N alone).
// Output: JSON {"x", "y", "x_values", "y_values", "rows": [{"x", "y", "spectral_radius", "angle",
// "error_estimate", "verdict"}], "stable_points", "undecided_points", ...}, angle = |arg mu_1| in
// [0, pi] (what tells a period-doubling lobe, pi, from a Neimark-Sacker one: crossing_type);
// with --out DIR also DIR/chart.csv: x,y,spectral_radius[,error_estimate,undecided],angle, one block per y value
// separated by a blank line (gnuplot's grid format), metadata as "#" comment lines first. A point that fails numerically (e.g. no
// periodic orbit) is recorded (spectral_radius null, its "failure"; nan in the CSV), the others still run, and the
// command exits 3 after writing everything, as sweep does.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>
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

namespace {

// What the command reads and checks before any work; the keys are read in this order (--help lists them so).
struct ChartSettings {
  ParameterAxis x, y;
  int threads = 1;
  Problem problem;  // read once, as every point will be
  OrbitSettings orbit_settings;
  bool with_error_bars = false;
  long count = 0;  // the grid's points, x fastest
};

// Reads and checks the axes, the problem and the solver keys (every point reads them again).
ChartSettings read_chart_settings(Config& config) {
  ChartSettings s;
  s.x = read_parameter_axis(config, "chart", "x", "delta", -1, 5, 31);
  s.y = read_parameter_axis(config, "chart", "y", "b", -1.5, 1.5, 31);
  if (s.x.name == s.y.name) throw BadInput("`chart_x = chart_y = " + s.x.name + "`: the two axes must differ");
  s.threads = read_threads(config);
  // Read (and validate) the problem once, as every point will. N = 200 by default: the levels of
  // the error bars, N/4 and N/2, must show the order (error_bars.hpp).
  s.problem = read_problem(config, 200);
  s.orbit_settings = read_orbit_settings(config);
  read_floquet_options(config, 1);
  // Each point's |mu_1| with its error bar and verdict (floquet's rule: error_bars.hpp), as floquet
  // gives them: a chart says which cells it cannot vouch for (undecided, drawn so).
  s.with_error_bars = config.get_switch("error_bars", true);
  require_model_parameter(config, "chart_x", s.x.name, s.problem.model_name);
  require_model_parameter(config, "chart_y", s.y.name, s.problem.model_name);
  config.check_all_used();
  s.count = grid_point_count(s.x, s.y, "chart");
  return s;
}

// Every point's result by index; a point with a failure has no radius, bar or verdict.
struct ChartPoints {
  explicit ChartPoints(long count)
      : radius(static_cast<size_t>(count), NAN),
        angle(static_cast<size_t>(count), NAN),
        failure(static_cast<size_t>(count)),
        bar(static_cast<size_t>(count), NAN),
        verdict(static_cast<size_t>(count), StabilityVerdict::undecided) {}
  std::vector<double> radius;
  std::vector<double> angle;  // |arg mu_1|
  std::vector<std::string> failure;
  std::vector<double> bar;  // error_estimate of |mu_1| (inf: none)
  std::vector<StabilityVerdict> verdict;  // with error bars (error_bars.hpp)
};

// The verdict a record's word names; none for any other word (a record is untrusted input).
std::optional<StabilityVerdict> verdict_named(const std::string& word) {
  for (StabilityVerdict v : {StabilityVerdict::stable, StabilityVerdict::unstable, StabilityVerdict::undecided})
    if (to_string(v) == word) return v;
  return std::nullopt;
}

// A point's record: its row of the result, its line in --out DIR's log (point_files.hpp), and its
// message to the lead under mpirun (distributed_points.hpp).
nlohmann::json chart_record(const ChartSettings& s, const ChartPoints& pts, long i) {
  nlohmann::json row = {{"index", i}, {"x", s.x.value(i % s.x.points)}, {"y", s.y.value(i / s.x.points)}};
  row["spectral_radius"] = pts.failure[i].empty() ? nlohmann::json(pts.radius[i]) : nlohmann::json(nullptr);
  if (pts.failure[i].empty()) row["angle"] = number_or_null(pts.angle[i]);
  else row["failure"] = pts.failure[i];
  if (s.with_error_bars && pts.failure[i].empty()) {
    row["error_estimate"] = number_or_null(pts.bar[i]);
    row["verdict"] = to_string(pts.verdict[i]);
  }
  return row;
}

// Keeps the result of a record (a resumed point, or a worker's); false: compute it again.
bool take_chart_record(const ChartSettings& s, ChartPoints& pts, long i, const nlohmann::json& row) {
  if (row.contains("failure")) {
    pts.failure[i] = row.at("failure").get<std::string>();
  } else {
    if (!row.contains("angle")) return false;  // a record of an older version: recompute
    pts.radius[i] = row.at("spectral_radius").is_number() ? row["spectral_radius"].get<double>() : NAN;
    pts.angle[i] = row["angle"].is_number() ? row["angle"].get<double>() : NAN;
  }
  if (s.with_error_bars && !row.contains("failure")) {
    // a record of a run without error bars, or a word that is no verdict: recompute
    const std::optional<StabilityVerdict> verdict =
        row.contains("verdict") && row.at("verdict").is_string() ? verdict_named(row["verdict"].get<std::string>())
                                                                 : std::nullopt;
    if (!verdict) return false;
    pts.verdict[i] = *verdict;
    pts.bar[i] = row.at("error_estimate").is_number() ? row["error_estimate"].get<double>() : INFINITY;
  }
  return true;
}

// Computes point i: |mu_1| at its orbit, with error_bars its bar and verdict.
void compute_chart_point(const Config& config, const ChartSettings& s, ChartPoints& pts, long i) {
  Config point = config;  // each point: its own copy with the two coordinates set
  point.set(s.x.name, format_number(s.x.value(i % s.x.points)), "chart");
  point.set(s.y.name, format_number(s.y.value(i / s.x.points)), "chart");
  const Problem p = read_problem(point, 40);
  const FloquetOptions options = read_floquet_options(point, 1);
  try {
    // The solve and its error bars (resolution_study.hpp; no retry from the point's orbit, which
    // is not kept: a chart has many points)
    const FloquetAtResolution at =
        resolution_study(p, s.orbit_settings, options).floquet(s.with_error_bars, /*retry_from_N=*/false);
    pts.radius[i] = std::abs(at.result.multipliers.at(0));
    pts.angle[i] = std::abs(std::arg(at.result.multipliers.at(0)));
    if (at.bars) {
      pts.verdict[i] = at.bars->verdict;
      pts.bar[i] = at.bars->bars.at(0).error_estimate;
    }
  } catch (const NumericalFailure& e) {
    pts.failure[i] = e.what();  // e.g. no periodic orbit at this point: reported, not fatal
  }
}

// The rows of the result and the counts the summary reports.
struct ChartTally {
  long stable = 0, undecided = 0, failed = 0;
  nlohmann::json rows = nlohmann::json::array();
};

// Stable: with error bars, the points whose verdict is stable (the bar inside the circle);
// without, |mu_1| < 1 as computed.
ChartTally tally_chart(const ChartSettings& s, const ChartPoints& pts) {
  ChartTally t;
  for (long i = 0; i < s.count; ++i) {
    nlohmann::json row = chart_record(s, pts, i);
    row.erase("index");
    if (!pts.failure[i].empty()) ++t.failed;
    else if (!s.with_error_bars) t.stable += pts.radius[i] < 1;
    else t.stable += pts.verdict[i] == StabilityVerdict::stable, t.undecided += pts.verdict[i] == StabilityVerdict::undecided;
    t.rows.push_back(row);
  }
  return t;
}

// --out DIR: chart.csv, one block per y value separated by a blank line (gnuplot's grid format).
void write_chart_csv(const Invocation& inv, const Config& config, const ChartSettings& s, const ChartPoints& pts,
                     const nlohmann::json& json, double seconds) {
  OutputFile csv(inv, std::filesystem::path(*inv.out_dir) / "chart.csv");
  OutputMetadata metadata = make_metadata("chart", inv.scene, config, json, seconds);
  name_model(metadata, s.problem.model_label, s.problem.state_names);
  csv.stream() << metadata_comment_lines(metadata);
  csv.stream() << s.x.name << "," << s.y.name << ",spectral_radius"
               << (s.with_error_bars ? ",error_estimate,undecided" : "") << ",angle\n";
  csv.stream().precision(12);
  for (long i = 0; i < s.count; ++i) {
    if (i > 0 && i % s.x.points == 0) csv.stream() << "\n";  // a blank line ends each y block
    csv.stream() << s.x.value(i % s.x.points) << "," << s.y.value(i / s.x.points) << ",";
    const bool ok = pts.failure[i].empty();
    if (ok) csv.stream() << pts.radius[i];
    else csv.stream() << "nan";
    // undecided: 1 where the circle is within the bar, 0 where a verdict was reached (nan: failed)
    if (s.with_error_bars)
      csv.stream() << "," << (ok && std::isfinite(pts.bar[i]) ? pts.bar[i] : NAN) << ","  // nan: no bar
                   << (ok ? (pts.verdict[i] == StabilityVerdict::undecided ? "1" : "0") : "nan");
    csv.stream() << "," << (ok ? pts.angle[i] : NAN) << "\n";
  }
  csv.commit();
}

// The text summary: the grid, the stable (and undecided, failed) points, the time.
void print_chart(const Invocation& inv, const ChartSettings& s, const ChartTally& t, double seconds) {
  const ParameterAxis &x = s.x, &y = s.y;
  inv.out << "delayspec chart: model " << s.problem.model_label << ", N = " << s.problem.N << ", " << x.name << " in ["
          << x.min << ", " << x.max << "] x " << y.name << " in [" << y.min << ", " << y.max << "], " << s.count
          << " points on " << s.threads << " threads\n";
  if (s.with_error_bars)
    inv.out << "stable (|mu_1| + its error bar < 1): " << t.stable << " of " << s.count << " points, undecided "
            << t.undecided;
  else inv.out << "stable (|mu_1| < 1): " << t.stable << " of " << s.count << " points";
  if (t.failed) inv.out << "; " << t.failed << " points failed (see --json)";
  inv.out << "\ntime: " << seconds << " s\n";
  if (inv.out_dir) inv.out << "wrote " << (std::filesystem::path(*inv.out_dir) / "chart.csv").string() << "\n";
}

}  // namespace

int command_chart(Config& config, const Invocation& inv) {
  const auto start = std::chrono::steady_clock::now();
  const ChartSettings s = read_chart_settings(config);
  if (const std::string note = autonomous_fixed_point_note(s.problem); !note.empty() && !inv.quiet)
    inv.err << "delayspec chart: note: " << note << "\n";
  ChartPoints pts(s.count);
  PointLoop loop{.command = "chart", .count = s.count, .threads = s.threads, .per_point_keys = {s.x.name, s.y.name}};
  loop.record = [&](long i) { return chart_record(s, pts, i); };
  loop.take = [&](long i, const nlohmann::json& row) { return take_chart_record(s, pts, i, row); };
  loop.compute = [&](long i) { compute_chart_point(config, s, pts, i); };
  run_point_loop(loop, config, inv);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const ChartTally t = tally_chart(s, pts);
  nlohmann::json json = grid_json(s.problem, s.x, s.y);
  if (s.with_error_bars) json["undecided_points"] = t.undecided;
  json.update(nlohmann::json{{"points", s.count},
                             {"stable_points", t.stable},
                             {"failed_points", t.failed},
                             {"threads", s.threads},
                             {"seconds", seconds},
                             {"rows", t.rows}});
  if (inv.out_dir) write_chart_csv(inv, config, s, pts, json, seconds);
  if (inv.json) inv.out << json.dump(2) << "\n";
  else print_chart(inv, s, t, seconds);
  return report_failed_points(inv.err, "chart", t.rows);
}

}  // namespace delayspec::cli
