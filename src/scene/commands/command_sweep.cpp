// delayspec sweep: one parameter over a range; at every point the leading Lyapunov exponents
// and the Poincare-section values x(t0 + jT) after the transient (bifurcation-diagram data).
//
// Points run in parallel (`threads`, default: all cores), each thread with its own stepper and
// buffers, and under mpirun over the ranks too (point_loop.hpp; docs/parallel.md). With --out
// DIR the results are kept point by point, so an interrupted sweep loses only the points in
// flight and `--resume` completes it:
//   DIR/sweep_settings.json     the effective settings of the sweep (resume refuses other settings)
//   DIR/points/rank_RRRRR.jsonl a line per finished point, appended by rank R, with the
//                               settings_hash of its sweep (resume refuses a point of another sweep)
//   DIR/exponents.csv           parameter,lambda1..k,se1..k,lambda1_per_time..,seconds
//   DIR/section.csv             parameter,x (one row per Poincare point)
// (both after the metadata comment lines, which name the swept key: `# sweep_key = K`)
//   DIR/sweep.json              summary (the --json output)
// The last three are written (atomically) only when every point is done.
// Exponents are per stroboscopic period (the paper's unit); *_per_time divide by period_time.
// A point whose run fails numerically is recorded with its reason (exponents null/nan), the
// other points still run, and the command exits 3 after writing everything.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <sstream>

#include <nlohmann/json.hpp>

#include "scene/output/output_directory.hpp"
#include "scene/commands/commands.hpp"
#include "scene/problem/lyapunov_settings.hpp"
#include "scene/output/metadata.hpp"
#include "scene/output/output.hpp"
#include "scene/problem/parameter_grid.hpp"  // read_threads
#include "scene/points/point_files.hpp"
#include "scene/points/point_loop.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct SweepPoint {
  long index = 0;
  double parameter = 0;
  Problem problem;
  json result;  // the point's record (also its line in the log)
};


double number_or_nan(const json& j) { return j.is_number() ? j.get<double>() : NAN; }

json point_record(const SweepPoint& p, const LyapunovResult& r, int d) {
  json j = lyapunov_json(r);
  j["index"] = p.index;
  j["parameter"] = p.parameter;
  std::vector<double> x(r.section.rows());
  for (long i = 0; i < r.section.rows(); ++i) x[i] = r.section(i, 0);
  j["section_x"] = x;
  if (d > 1) {
    std::vector<double> v(r.section.rows());
    for (long i = 0; i < r.section.rows(); ++i) v[i] = r.section(i, 1);
    j["section_v"] = v;
  }
  j["seconds"] = r.seconds;
  return j;
}

// What the command reads and checks before any work.
struct SweepSettings {
  std::string key;  // the swept parameter
  double from = 0, to = 0;
  long count = 0;
  int threads = 1;  // read_threads: 0 in the key = all cores
  long section_points = 0;
  LyapunovOptions options;
  Problem first;                   // the problem at sweep_from
  std::vector<SweepPoint> points;  // every point's problem, validated
};

SweepSettings read_sweep_settings(Config& config) {
  SweepSettings s;
  if (!config.has("sweep_key")) throw BadInput("missing key `sweep_key` (the parameter to sweep, e.g. k)");
  s.key = config.get_string("sweep_key", "");
  for (const char* reserved : {"sweep_key", "sweep_from", "sweep_to", "sweep_points", "threads", "section_points",
                               "exponents", "periods", "transient", "seed", "qr_every", "batches", "model"})
    if (s.key == reserved) throw BadInput("`sweep_key = " + s.key + "`: not a parameter that can be swept");
  s.from = config.require_double("sweep_from");
  s.to = config.require_double("sweep_to");
  require_finite_width("`sweep_from = " + format_number(s.from) + "`, `sweep_to = " + format_number(s.to) + "`", s.from,
                       s.to);
  s.count = config.get_int_in_range("sweep_points", 11, 1, 1'000'000);
  s.threads = read_threads(config);
  // section points are kept in memory (d doubles each) for every point of the sweep
  s.section_points = config.get_int_in_range("section_points", 100, 0, 10'000'000);
  s.options = read_lyapunov_options(config, 2);
  s.options.section_points = s.section_points;
  // The swept key takes each point's value; reading the problem once with the first value
  // validates it and marks the key as used (a key no model reads is then reported as unknown).
  config.set(s.key, format_number(s.from), "sweep_from");
  s.first = read_problem(config, 100);
  config.check_all_used();

  s.points.resize(static_cast<size_t>(s.count));
  for (long i = 0; i < s.count; ++i) {
    SweepPoint& p = s.points[i];
    p.index = i;
    p.parameter =
        s.count == 1 ? s.from : s.from + (s.to - s.from) * static_cast<double>(i) / static_cast<double>(s.count - 1);
    Config point_config = config;
    point_config.set(s.key, format_number(p.parameter), "sweep point " + std::to_string(i));
    p.problem = read_problem(point_config, 100);  // BadInput here names the key and the value
    validate_lyapunov_options(s.options, p.problem.dimension());
  }
  return s;
}

// The tables of a finished sweep: exponents.csv and section.csv (without the metadata header),
// and the points' records with the failed ones listed.
struct SweepTables {
  std::string exponents_csv, section_csv;
  json points = json::array(), failed = json::array();
};

SweepTables sweep_tables(const std::vector<SweepPoint>& points, int k) {
  SweepTables t;
  std::ostringstream exponents_csv, section_csv;
  exponents_csv << "parameter";
  for (int i = 1; i <= k; ++i) exponents_csv << ",lambda" << i;
  for (int i = 1; i <= k; ++i) exponents_csv << ",se" << i;
  for (int i = 1; i <= k; ++i) exponents_csv << ",lambda" << i << "_per_time";
  exponents_csv << ",seconds\n";
  section_csv << "parameter,x\n";
  for (const SweepPoint& p : points) {
    const json& r = p.result;
    const bool ok = !r.contains("error");
    if (!ok) t.failed.push_back({{"parameter", p.parameter}, {"error", r["error"]}});
    exponents_csv << csv_number(p.parameter);
    for (const char* field : {"exponents_per_period", "standard_error_per_period", "exponents_per_time"})
      for (int i = 0; i < k; ++i) exponents_csv << "," << csv_number(ok ? number_or_nan(r[field][i]) : NAN);
    exponents_csv << "," << csv_number(ok ? number_or_nan(r["seconds"]) : NAN) << "\n";
    if (ok)
      for (const auto& x : r["section_x"])
        section_csv << csv_number(p.parameter) << "," << csv_number(number_or_nan(x)) << "\n";
    t.points.push_back(r);
  }
  t.exponents_csv = exponents_csv.str();
  t.section_csv = section_csv.str();
  return t;
}

}  // namespace

int command_sweep(Config& config, const Invocation& inv) {
  const auto start = std::chrono::steady_clock::now();
  // Read and check.
  SweepSettings s = read_sweep_settings(config);
  const LyapunovOptions& options = s.options;
  const int d = s.first.state_dimension();
  const std::string hash = settings_hash(resume_settings(config, {s.key}));  // the point records' label
  // Compute the points not done yet, in parallel (threads, and ranks under mpirun); with
  // --out DIR a point's record is logged as it finishes, by the rank that computed it.
  PointLoop loop{.command = "sweep", .count = s.count, .threads = s.threads, .per_point_keys = {s.key}};
  loop.compute = [&](long index) {
    SweepPoint& p = s.points[static_cast<size_t>(index)];
    try {
      p.result = point_record(p, run_lyapunov(p.problem, options), d);
    } catch (const NumericalFailure& e) {
      p.result = {{"index", p.index}, {"parameter", p.parameter}, {"error", e.what()}};
    }
    p.result["settings_hash"] = hash;
  };
  loop.record = [&](long index) { return s.points[static_cast<size_t>(index)].result; };
  loop.take = [&](long index, const json& record) {
    SweepPoint& p = s.points[static_cast<size_t>(index)];
    if (record.at("parameter").get<double>() != p.parameter) return false;
    p.result = record;
    return true;
  };
  const long todo_count = run_point_loop(loop, config, inv);
  const long thread_count = std::clamp<long>(s.threads, 1, std::max<long>(todo_count, 1));  // as parallel_points

  // Report: the tables and the summary.
  const SweepTables tables = sweep_tables(s.points, options.exponents);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  json summary;
  summary["points"] = tables.points;
  summary["model"] = s.first.model_name;
  summary["sweep_key"] = s.key;
  summary["sweep_from"] = s.from;
  summary["sweep_to"] = s.to;
  summary["sweep_points"] = s.count;
  summary["N"] = s.first.N;
  summary["exponents"] = options.exponents;
  summary["periods"] = options.periods;
  summary["transient"] = options.transient;
  summary["qr_every"] = options.qr_every;
  summary["seed"] = options.seed;
  summary["section_points"] = s.section_points;
  summary["events"] = to_string(s.first.events);
  summary["jacobian"] = to_string(s.first.jacobian);
  summary["threads"] = thread_count;
  summary["points_computed_now"] = todo_count;
  summary["failed"] = tables.failed;
  summary["seconds"] = seconds;
  if (inv.out_dir) {
    const fs::path dir(*inv.out_dir);
    // The files carry the metadata header (it names the swept key: `plot` labels the x axis
    // with it); the swept key's own value is per row, so it is not a metadata line.
    OutputMetadata metadata = make_metadata("sweep", inv.scene, config, summary, seconds);
    metadata.parameters.erase(s.key);
    name_model(metadata, s.first.model_label, s.first.state_names);  // section.csv's x: the first
    const std::string header = metadata_comment_lines(metadata);
    write_output(inv, dir / "exponents.csv", header + tables.exponents_csv);
    write_output(inv, dir / "section.csv", header + tables.section_csv);
    write_output(inv, dir / "sweep.json", summary.dump(1) + "\n");
  }

  if (inv.json) {
    inv.out << summary.dump(1) << "\n";
  } else {
    inv.out << "delayspec sweep: model " << s.first.model_label << ", " << s.key << " from " << s.from << " to " << s.to
            << " (" << s.count << " points, " << thread_count << " threads), N = " << s.first.N << ", transient "
            << options.transient << ", periods " << options.periods << "\n";
    inv.out << tables.exponents_csv;
    if (inv.out_dir) {
      const fs::path dir(*inv.out_dir);
      inv.out << "files: " << (dir / "exponents.csv").string() << ", " << (dir / "section.csv").string() << ", "
              << (dir / "sweep.json").string() << "\n";
    }
    inv.out << "time: " << seconds << " s\n";
  }
  if (!tables.failed.empty()) {
    inv.err << "delayspec sweep: numerical failure at " << tables.failed.size() << " point(s), first: parameter "
            << tables.failed[0]["parameter"].get<double>() << ": " << tables.failed[0]["error"].get<std::string>()
            << "\n";
    return 3;
  }
  return 0;
}

}  // namespace delayspec::cli
