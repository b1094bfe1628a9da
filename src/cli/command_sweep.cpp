// delayspec sweep: one parameter over a range; at every point the leading Lyapunov exponents
// and the Poincare-section values x(t0 + jT) after the transient (bifurcation-diagram data).
//
// Points run in parallel (`threads`, default: all cores), each thread with its own stepper and
// buffers. With --out DIR the results are kept point by point, so an interrupted sweep loses
// only the points in flight and `--resume` completes it:
//   DIR/sweep_settings.json     the effective settings of the sweep (resume refuses other settings)
//   DIR/points/point_NNNNN.json one file per finished point, written atomically, with the
//                               settings_hash of its sweep (resume refuses a point of another sweep)
//   DIR/exponents.csv           parameter,lambda1..k,se1..k,lambda1_per_time..,seconds
//   DIR/section.csv             parameter,x (one row per Poincare point)
// (both after the metadata comment lines, which name the swept key: `# sweep_key = K`)
//   DIR/sweep.json              summary (the --json output)
// The last three are written (atomically) only when every point is done.
// Exponents are per stroboscopic period (the paper's unit); *_per_time divide by period_time.
// A point whose run fails numerically is recorded with its reason (exponents null/nan), the
// other points still run, and the command exits 3 after writing everything.
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

#include <nlohmann/json.hpp>

#include "atomic_file.hpp"
#include "commands.hpp"
#include "lyapunov_settings.hpp"
#include "metadata.hpp"
#include "problem.hpp"
#include "progress.hpp"

namespace delayspec::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct SweepPoint {
  long index = 0;
  double parameter = 0;
  Problem problem;
  json result;  // the point's record (also its file)
  bool done = false;
};

// FNV-1a (64 bit) of the settings' JSON text, as 16 hex digits: a point file's label of the
// sweep it belongs to (nlohmann::json keeps object keys sorted, so the text is canonical).
std::string settings_hash(const json& settings) {
  std::uint64_t hash = 14695981039346656037ull;
  for (const unsigned char c : settings.dump()) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  return hex;
}

std::string csv_number(double x) { return std::isfinite(x) ? format_number(x) : "nan"; }

double number_or_nan(const json& j) { return j.is_number() ? j.get<double>() : NAN; }

json point_record(const SweepPoint& p, const LyapunovResult& r, int d) {
  json j;
  j["index"] = p.index;
  j["parameter"] = p.parameter;
  j["exponents_per_period"] = r.per_period;
  j["standard_error_per_period"] = r.standard_error_per_period;
  j["exponents_per_time"] = r.per_time;
  j["standard_error_per_time"] = r.standard_error_per_time;
  j["batch_standard_error_per_period"] = r.batch_standard_error_per_period;
  j["fluctuation_bound_per_period"] = r.fluctuation_bound_per_period;
  j["period_time"] = r.map_time;
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

fs::path point_path(const fs::path& dir, long index) {
  char name[32];
  std::snprintf(name, sizeof name, "point_%05ld.json", index);
  return dir / "points" / name;
}

}  // namespace

int command_sweep(Config& config, const Invocation& inv) {
  const auto start = std::chrono::steady_clock::now();
  if (!config.has("sweep_key")) throw BadInput("missing key `sweep_key` (the parameter to sweep, e.g. k)");
  const std::string key = config.get_string("sweep_key", "");
  for (const char* reserved : {"sweep_key", "sweep_from", "sweep_to", "sweep_points", "threads", "section_points",
                               "exponents", "periods", "transient", "seed", "qr_every", "batches", "model"})
    if (key == reserved) throw BadInput("`sweep_key = " + key + "`: not a parameter that can be swept");
  const double from = config.require_double("sweep_from");
  const double to = config.require_double("sweep_to");
  const long count = config.get_int_in_range("sweep_points", 11, 1, 1'000'000);
  const long threads_key = config.get_int_in_range("threads", 0, 0, 4096);  // 0 = all cores
  // section points are kept in memory (d doubles each) for every point of the sweep
  const long section_points = config.get_int_in_range("section_points", 100, 0, 10'000'000);
  LyapunovOptions options = read_lyapunov_options(config, 2);
  options.section_points = section_points;
  // The swept key takes each point's value; reading the problem once with the first value
  // validates it and marks the key as used (a key no model reads is then reported as unknown).
  config.set(key, format_number(from), "sweep_from");
  Problem first = read_problem(config, 100);
  config.check_all_used();

  std::vector<SweepPoint> points(static_cast<size_t>(count));
  for (long i = 0; i < count; ++i) {
    SweepPoint& p = points[i];
    p.index = i;
    p.parameter = count == 1 ? from : from + (to - from) * static_cast<double>(i) / static_cast<double>(count - 1);
    Config point_config = config;
    point_config.set(key, format_number(p.parameter), "sweep point " + std::to_string(i));
    p.problem = read_problem(point_config, 100);  // BadInput here names the key and the value
    validate_lyapunov_options(options, p.problem.dimension());
  }
  const int d = first.state_dimension();

  // Settings of the sweep for --resume: the effective values (a key stated at its default equals
  // the key left out), except the thread count (results do not depend on it) and the scene-level
  // keys of `run` (analyses, title).
  json settings = json::object();
  for (const auto& [k, v] : config.effective_values())
    if (k != "threads" && k != "analyses" && k != "title") settings[k] = v;
  settings[key] = nullptr;  // the swept key's value is per point
  const std::string hash = settings_hash(settings);
  std::optional<fs::path> dir;
  if (inv.out_dir) {
    dir = fs::path(*inv.out_dir);
    const fs::path settings_path = *dir / "sweep_settings.json";
    if (inv.resume) {
      std::ifstream in(settings_path);
      if (!in) throw BadInput("`--resume`: `" + settings_path.string() + "` not found (no sweep to resume there)");
      json stored;
      try {
        stored = json::parse(in);
      } catch (const std::exception&) {
        throw BadInput("`--resume`: `" + settings_path.string() + "` is not valid JSON");
      }
      if (stored != settings) {
        // Name each differing key with both values (a missing key shows as null).
        std::string diff;
        auto add = [&](const std::string& k) {
          diff += (diff.empty() ? "`" : ", `") + k + "` (now " + settings.value(k, json()).dump() + ", the sweep's " +
                  (stored.is_object() ? stored.value(k, json()) : json()).dump() + ")";
        };
        for (const auto& [k, v] : settings.items())
          if (!stored.is_object() || !stored.contains(k) || stored[k] != v) add(k);
        if (stored.is_object())
          for (const auto& [k, v] : stored.items())
            if (!settings.contains(k)) add(k);
        throw BadInput("`--resume`: the settings differ from the interrupted sweep in " + diff);
      }
      for (SweepPoint& p : points) {
        const fs::path path = point_path(*dir, p.index);
        std::ifstream pin(path);
        if (!pin) continue;
        json record;
        try {
          record = json::parse(pin);
        } catch (const std::exception&) {
          continue;  // unreadable point file: recompute the point
        }
        // A point of another sweep (other settings) is never merged into this one.
        const json stored_hash = record.is_object() ? record.value("settings_hash", json()) : json();
        if (stored_hash != hash)
          throw BadInput("`--resume`: `" + path.string() + "` belongs to a sweep with other settings (settings_hash " +
                         (stored_hash.is_string() ? stored_hash.get<std::string>() : std::string("missing")) +
                         ", this sweep " + hash + ", settings in " + settings_path.string() +
                         "): remove the file, or resume with the settings it was computed with");
        try {
          if (record.at("index").get<long>() == p.index && record.at("parameter").get<double>() == p.parameter) {
            p.result = record;
            p.done = true;
          }
        } catch (const std::exception&) {
          // a point record without index/parameter: recompute the point
        }
      }
    } else {
      if (fs::exists(settings_path) || fs::exists(*dir / "points"))
        throw BadInput("`--out " + dir->string() +
                       "` already holds a sweep: add --resume to complete it, or choose another directory");
      write_file_atomically(settings_path, settings.dump(2) + "\n");
    }
  }

  std::vector<SweepPoint*> todo;
  for (SweepPoint& p : points)
    if (!p.done) todo.push_back(&p);
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  const long thread_count =
      std::max<long>(1, std::min<long>(threads_key == 0 ? hardware : threads_key, static_cast<long>(todo.size())));
  if (!inv.quiet && inv.resume)
    inv.err << "sweep: resuming, " << (count - static_cast<long>(todo.size())) << " of " << count
            << " points already done\n";

  Progress progress(inv.err, "sweep", static_cast<long>(todo.size()), inv.quiet);
  std::atomic<size_t> next{0};
  std::atomic<bool> stop{false};
  std::exception_ptr fatal;
  std::mutex fatal_mutex;
  auto worker = [&] {
    while (!stop) {
      const size_t i = next++;
      if (i >= todo.size()) return;
      SweepPoint& p = *todo[i];
      try {
        try {
          p.result = point_record(p, run_lyapunov(p.problem, options), d);
        } catch (const NumericalFailure& e) {
          p.result = {{"index", p.index}, {"parameter", p.parameter}, {"error", e.what()}};
        }
        p.result["settings_hash"] = hash;
        if (dir) write_file_atomically(point_path(*dir, p.index), p.result.dump() + "\n");
        p.done = true;
        progress.add();
      } catch (...) {
        std::lock_guard<std::mutex> lock(fatal_mutex);
        if (!fatal) fatal = std::current_exception();
        stop = true;
      }
    }
  };
  std::vector<std::thread> pool;
  for (long t = 0; t < thread_count; ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  progress.finish();
  if (fatal) std::rethrow_exception(fatal);

  // Everything is done: the tables and the summary.
  const int k = options.exponents;
  std::ostringstream exponents_csv, section_csv;
  exponents_csv << "parameter";
  for (int i = 1; i <= k; ++i) exponents_csv << ",lambda" << i;
  for (int i = 1; i <= k; ++i) exponents_csv << ",se" << i;
  for (int i = 1; i <= k; ++i) exponents_csv << ",lambda" << i << "_per_time";
  exponents_csv << ",seconds\n";
  section_csv << "parameter,x\n";
  json summary;
  json failed = json::array();
  for (const SweepPoint& p : points) {
    const json& r = p.result;
    const bool ok = !r.contains("error");
    if (!ok) failed.push_back({{"parameter", p.parameter}, {"error", r["error"]}});
    exponents_csv << csv_number(p.parameter);
    for (const char* field : {"exponents_per_period", "standard_error_per_period", "exponents_per_time"})
      for (int i = 0; i < k; ++i) exponents_csv << "," << csv_number(ok ? number_or_nan(r[field][i]) : NAN);
    exponents_csv << "," << csv_number(ok ? number_or_nan(r["seconds"]) : NAN) << "\n";
    if (ok)
      for (const auto& x : r["section_x"]) section_csv << csv_number(p.parameter) << "," << csv_number(number_or_nan(x)) << "\n";
    summary["points"].push_back(r);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary["model"] = first.model_name;
  summary["sweep_key"] = key;
  summary["sweep_from"] = from;
  summary["sweep_to"] = to;
  summary["sweep_points"] = count;
  summary["N"] = first.N;
  summary["exponents"] = k;
  summary["periods"] = options.periods;
  summary["transient"] = options.transient;
  summary["qr_every"] = options.qr_every;
  summary["seed"] = options.seed;
  summary["section_points"] = section_points;
  summary["events"] = to_string(first.events);
  summary["jacobian"] = to_string(first.jacobian);
  summary["threads"] = thread_count;
  summary["points_computed_now"] = todo.size();
  summary["failed"] = failed;
  summary["seconds"] = seconds;
  if (dir) {
    // The files carry the metadata header (it names the swept key: `plot` labels the x axis
    // with it); the swept key's own value is per row, so it is not a metadata line.
    OutputMetadata metadata = make_metadata("sweep", inv.scene, config, summary, seconds);
    metadata.parameters.erase(key);
    const std::string header = metadata_comment_lines(metadata);
    write_file_atomically(*dir / "exponents.csv", header + exponents_csv.str());
    write_file_atomically(*dir / "section.csv", header + section_csv.str());
    write_file_atomically(*dir / "sweep.json", summary.dump(1) + "\n");
  }

  if (inv.json) {
    inv.out << summary.dump(1) << "\n";
  } else {
    inv.out << "delayspec sweep: model " << first.model_name << ", " << key << " from " << from << " to " << to << " ("
            << count << " points, " << thread_count << " threads), N = " << first.N << ", transient "
            << options.transient << ", periods " << options.periods << "\n";
    inv.out << exponents_csv.str();
    if (dir) inv.out << "files: " << (*dir / "exponents.csv").string() << ", " << (*dir / "section.csv").string() << ", "
                     << (*dir / "sweep.json").string() << "\n";
    inv.out << "time: " << seconds << " s\n";
  }
  if (!failed.empty()) {
    inv.err << "delayspec sweep: numerical failure at " << failed.size() << " point(s), first: parameter "
            << failed[0]["parameter"].get<double>() << ": " << failed[0]["error"].get<std::string>() << "\n";
    return 3;
  }
  return 0;
}

}  // namespace delayspec::cli
