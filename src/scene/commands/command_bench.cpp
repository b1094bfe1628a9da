// delayspec bench: the same problem solved by the Krylov and the dense eigen-solvers at several
// N, in one run: time, peak memory, operator applications and error against a reference
// (CLI contract `bench`). Library parts: floquet.hpp, convergence.hpp.
//
// Keys: Ns (comma list) or N_min/N_max (doubling); solvers (comma list of spectra, arpack, block,
// dense-lapack, dense-eigen; default all but dense-eigen; and the classic dense discretisations
// sdm0, fdm1 of linear models with tau = T, classic_discretisation.hpp: their N is m, the steps
// per period, and their seconds include forming the product; classic_max_N, default 640: they
// run at the listed N up to this one only, their cost being O(N^3)); nev (default 10), ncv, tol,
// max_restarts, seed; reference = exact | extrapolated | finest | auto (the reference values:
// exact multipliers, or Richardson / the finest level of the solver with the most levels);
// dense_memory_limit_mb (default 2048): a dense row whose matrices would need more is skipped
// with a message instead of exhausting the machine's memory; repeats (default 3): each solve is
// timed this often and the fastest is reported, the slowest beside it (solves over 1 s once: a
// single run at the coarsest N is the noisiest figure of a speed plot); the problem's and orbit's
// keys.
//
// Per row: seconds (the fastest eigen-solve, incl. forming the dense matrix), seconds_slowest (the
// slowest of the repeats: the spread), setup_seconds (orbit and
// step maps, shared by the solvers of one N), peak_bytes (memory_probe.hpp: what the solve added
// at its peak), error (relative, leading multiplier), max_error (over the nev), correct_digits,
// abs_error (relative error of |mu_1|: what a stability boundary |mu_1| = 1 depends on; the
// phase of mu_1 can be much less accurate, milling: docs/milling.md),
// deviation_from_dense (max |mu_k - mu_k^dense| / |mu_1^dense| at the same N, when dense ran).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "scene/output/output_directory.hpp"
#include "scene/commands/commands.hpp"
#include "delayspec/classic_result.hpp"
#include "delayspec/convergence.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/linear_algebra_libraries.hpp"
#include "scene/problem/floquet_settings.hpp"
#include "scene/problem/level_runner.hpp"
#include "scene/problem/models_module_loader.hpp"
#include "scene/output/memory_probe.hpp"
#include "scene/output/metadata.hpp"
#include "scene/output/output.hpp"
#include "scene/output/progress.hpp"

namespace delayspec::cli {

namespace {

struct BenchRow {
  int N = 0;
  long n = 0;
  std::string solver;
  std::string status = "ok";  // ok | skipped | failed
  std::string message;
  Multipliers multipliers;
  double seconds = NAN, setup_seconds = NAN;
  double seconds_slowest = NAN;  // of the repeats
  long peak_bytes = -1;
  long operator_applications = 0;  // of one solve
  int repeats = 0;                 // solves timed (seconds = the fastest)
  double error = NAN, max_error = NAN, correct_digits = NAN, deviation_from_dense = NAN;
  double abs_error = NAN;  // relative error of |mu_1|
};

bool is_dense(FloquetSolver s) { return s == FloquetSolver::dense_lapack || s == FloquetSolver::dense_eigen; }

// The classic reference discretisations (not solvers of delayspec's map: their own maps).
const std::vector<std::string>& classic_names() {
  static const std::vector<std::string> names = {"sdm0", "fdm1"};
  return names;
}
bool is_classic(const std::string& name) {
  return std::find(classic_names().begin(), classic_names().end(), name) != classic_names().end();
}
ClassicMethod parse_classic(const std::string& name) {
  return name == "sdm0" ? ClassicMethod::sdm0 : ClassicMethod::fdm1;
}
// A row of a dense delayspec solver (the `vs dense` comparison and the speed-up line use them).
bool is_dense_row(const std::string& solver) { return !is_classic(solver) && is_dense(parse_floquet_solver(solver)); }

// Bytes the dense path holds at its peak: the assembled matrix, the copy LAPACK overwrites (or
// Eigen's Schur form), and the QR workspace / Householder blocks: about 3 n^2 doubles.
double dense_bytes_estimate(long n) { return 3.0 * 8.0 * static_cast<double>(n) * static_cast<double>(n); }

// What bench reads and checks before any work.
struct BenchSettings {
  Problem problem;
  OrbitSettings orbit;
  std::vector<int> Ns;
  std::vector<std::string> solver_names;   // as given (`dense` stays `dense`)
  std::vector<FloquetSolver> solvers;      // delayspec's
  std::vector<ClassicMethod> classics;     // the classic discretisations listed
  std::vector<std::string> classic_names;  // their names, in the order listed
  FloquetOptions base;                     // nev, ncv, tol, ... (the solver is set per row)
  ReferenceKind reference_kind = ReferenceKind::automatic;
  long repeats = 3;
  double limit_mb = 2048;
  long classic_max_N = 640;  // the classic rows stop here (O(N^3) each)
  Multipliers exact;         // reference multipliers no step map produced, when the model has them
  double exact_precision = 1e-14;  // their relative accuracy
  std::string exact_source;        // lambert_w or spectral (level_runner.hpp's exact_reference)
};

BenchSettings read_bench_settings(Config& config) {
  BenchSettings s;
  // bench compares several solvers: `solver` on the command line is a mistake; in a scene shared
  // with floquet it is floquet's key (ignored here).
  if (config.has("solver") && config.origin("solver") == "--set")
    throw BadInput("`solver = " + config.get_string("solver", "") +
                   "`: bench compares several: use `solvers` (a comma list)");
  use_first_level_as_N(config);
  s.problem = read_problem(config, 100);
  s.orbit = read_orbit_settings(config);
  s.Ns = read_N_list(config, s.problem, 100, 400);
  s.solver_names =
      read_word_list(config, "solvers", "spectra,arpack,dense-lapack",
                     {"spectra", "arpack", "block", "dense", "dense-lapack", "dense-eigen", "sdm0", "fdm1"});
  s.base = read_floquet_options(config, 10);
  s.reference_kind = read_reference_kind(config);
  s.repeats = config.get_int_in_range("repeats", s.repeats, 1, 1000);
  s.classic_max_N = config.get_int_in_range("classic_max_N", s.classic_max_N, 2, 1'000'000);
  s.limit_mb = config.get_double("dense_memory_limit_mb", 2048);
  require_positive("dense_memory_limit_mb", s.limit_mb);
  config.check_all_used();

  for (const auto& name : s.solver_names) {
    if (is_classic(name)) {
      s.classics.push_back(parse_classic(name));
      s.classic_names.push_back(name);
    } else {
      s.solvers.push_back(parse_floquet_solver(name));
    }
  }
  if (!s.classics.empty()) {
    // Checked now, before any work: the classic paths need a linear model with tau = T.
    const std::string key = "`solvers = " + s.classic_names.front() + "`: ";
    try {
      builtin_classic_multipliers(s.problem, 2, s.classics.front(), 1);
    } catch (const BadInput& e) {
      throw BadInput(key + e.what());
    }
    if (s.Ns.front() < 2) throw BadInput(key + "the classic discretisations need N >= 2");
    if (s.problem.orbit_period != 1) throw BadInput(key + "the classic discretisations need orbit_period = 1");
  }
  Problem coarsest = s.problem;
  coarsest.N = s.Ns.front();
  const long n_min = coarsest.dimension();  // the dimension at the coarsest N, the smallest
  validate_floquet_options(s.base, n_min);
  // A Krylov row with nev > n - 2 would run the dense path (floquet.hpp): not a comparison.
  const bool krylov_listed =
      std::any_of(s.solvers.begin(), s.solvers.end(), [](FloquetSolver f) { return !is_dense(f); });
  if (krylov_listed && s.base.nev > n_min - 2)
    throw BadInput("`nev = " + std::to_string(s.base.nev) + "`: the Krylov solvers need nev <= n - 2 = " +
                   std::to_string(n_min - 2) + " at the coarsest N = " + std::to_string(s.Ns.front()));
  const ExactReference exact = exact_reference(s.problem, s.base.nev);
  s.exact = exact.multipliers;
  s.exact_precision = exact.precision;
  s.exact_source = exact.source;
  if (s.reference_kind == ReferenceKind::exact && s.exact.empty())
    throw BadInput("`reference = exact`: model `" + s.problem.model_name + "` has no exact multipliers");
  return s;
}

// Repeats: the minimum time is the least disturbed by other processes. A solve that took more
// than a second is not repeated (its noise is relatively small). solve() returns its seconds;
// row.seconds holds the first solve's.
template <class Solve>
void keep_fastest_of_repeats(BenchRow& row, long repeats, Solve&& solve) {
  row.seconds_slowest = row.seconds;
  for (row.repeats = 1; row.repeats < repeats && row.seconds < 1.0; ++row.repeats) {
    const double seconds = solve();
    row.seconds = std::min(row.seconds, seconds);
    row.seconds_slowest = std::max(row.seconds_slowest, seconds);
  }
}

void record_failure(BenchRow& row, const NumericalFailure& e, const Invocation& inv) {
  row.status = "failed";
  row.message = e.what();
  inv.err << "bench: N = " << row.N << ", " << row.solver << ": failed: " << e.what() << "\n";
}

// Every solver at every N: one row each (ok, skipped for memory, or failed numerically).
std::vector<BenchRow> run_bench(const BenchSettings& s, const Invocation& inv) {
  const std::vector<FloquetSolver>& solvers = s.solvers;
  const FloquetOptions& base = s.base;
  const long repeats = s.repeats;
  const double limit_mb = s.limit_mb;
  std::vector<BenchRow> rows;
  // Loading the libraries on first use (~2.5 ms) is no solver's time: done before any row.
  load_linear_algebra();
  long planned = static_cast<long>(s.Ns.size() * solvers.size());
  for (int N : s.Ns) planned += N <= s.classic_max_N ? static_cast<long>(s.classics.size()) : 0;
  Progress progress(inv.err, "bench", planned, inv.quiet);
  for (int N : s.Ns) {
    for (size_t c = 0; c < s.classics.size() && N <= s.classic_max_N; ++c) {
      BenchRow row;
      row.N = N;
      row.solver = s.classic_names[c];
      try {
        const MemoryProbe probe;
        const ClassicResult r = builtin_classic_multipliers(s.problem, N, s.classics[c], base.nev);
        row.peak_bytes = probe.peak_bytes();
        row.n = r.dimension;
        row.multipliers = r.multipliers;
        row.seconds = r.seconds;
        keep_fastest_of_repeats(row, repeats, [&] {
          return builtin_classic_multipliers(s.problem, N, s.classics[c], base.nev).seconds;
        });
      } catch (const NumericalFailure& e) {
        record_failure(row, e, inv);
      }
      rows.push_back(row);
      progress.add();
    }
    if (solvers.empty()) continue;
    with_monodromy(
        s.problem, s.problem.events, s.orbit, N, [&](const LinearOperator& op, const LinearisedOrbit&, double setup) {
          for (FloquetSolver solver : solvers) {
            BenchRow row;
            row.N = N;
            row.n = op.rows();
            row.solver = to_string(solver);
            row.setup_seconds = setup;
            const double need_mb = dense_bytes_estimate(row.n) / (1024.0 * 1024.0);
            if (is_dense(solver) && need_mb > limit_mb) {
              char buf[200];
              std::snprintf(buf, sizeof buf,
                            "dense needs about %.0f MB (3 n^2 doubles, n = %ld) > dense_memory_limit_mb = %g", need_mb,
                            row.n, limit_mb);
              row.status = "skipped";
              row.message = buf;
              inv.err << "bench: N = " << N << ", " << row.solver << ": skipped: " << buf << "\n";
            } else {
              FloquetOptions o = base;
              o.solver = solver;
              try {
                const MemoryProbe probe;
                const FloquetResult r = floquet_multipliers(op, o);
                row.peak_bytes = probe.peak_bytes();
                row.multipliers = r.multipliers;
                row.seconds = r.seconds;
                row.operator_applications = r.operator_applications;
                if (!r.note.empty()) row.message = r.note;
                keep_fastest_of_repeats(row, repeats, [&] { return floquet_multipliers(op, o).seconds; });
              } catch (const NumericalFailure& e) {
                record_failure(row, e, inv);
              }
            }
            rows.push_back(row);
            progress.add();
          }
        });
  }
  progress.finish();
  return rows;
}

// The reference values the rows are scored against.
struct BenchReference {
  Multipliers values;
  std::vector<double> precision;
  std::string used = "none", note;
};

// Exact when available (and not refused), else from the solver with the most completed levels
// (first listed on ties): Richardson extrapolation or its finest level.
BenchReference bench_reference(const BenchSettings& s, const std::vector<BenchRow>& rows) {
  BenchReference reference;
  if (!s.exact.empty() && (s.reference_kind == ReferenceKind::exact || s.reference_kind == ReferenceKind::automatic)) {
    reference.values = s.exact;
    reference.precision.assign(reference.values.size(), s.exact_precision);
    reference.used = "exact";
  } else {
    std::string best;
    size_t best_count = 0;
    for (const auto& name : s.solver_names) {
      if (is_classic(name)) continue;  // the reference is delayspec's (the classic rows are scored)
      const std::string canonical = to_string(parse_floquet_solver(name));
      size_t count = 0;
      for (const auto& r : rows) count += r.solver == canonical && r.status == "ok";
      if (count > best_count) best_count = count, best = canonical;
    }
    if (best_count >= 2) {
      ConvergenceOptions co;
      co.nev = s.base.nev;
      co.extra = 0;
      co.reference = s.reference_kind == ReferenceKind::finest ? ReferenceKind::finest : ReferenceKind::extrapolated;
      std::vector<LevelResult> levels;
      for (const auto& r : rows)
        if (r.solver == best && r.status == "ok") {
          co.Ns.push_back(r.N);
          LevelResult level;
          level.multipliers = r.multipliers;
          level.seconds = r.seconds;
          level.operator_applications = r.operator_applications;
          levels.push_back(std::move(level));
        }
      const ConvergenceStudy study = analyse_convergence(levels, co);
      reference.values = study.reference_values;
      reference.precision = study.reference_precision;
      reference.used = to_string(study.reference);
      reference.note = "from the " + best + " rows";
    } else {
      reference.note = "no exact values and fewer than two completed levels: errors not computed";
    }
  }
  return reference;
}

// error, max_error, correct_digits against the reference; deviation_from_dense at the same N.
void score_rows(std::vector<BenchRow>& rows, const BenchReference& reference) {
  for (auto& r : rows) {
    if (r.status != "ok") continue;
    if (!reference.values.empty()) {
      const MatchedErrors m = errors_against(r.multipliers, reference.values, reference.precision);
      r.error = m.errors[0];
      r.max_error = *std::max_element(m.errors.begin(), m.errors.end());
      r.correct_digits = m.correct_digits[0];
      r.abs_error = std::abs(std::abs(m.matched[0]) / std::abs(reference.values[0]) - 1);
    }
    for (const auto& dense : rows)
      if (dense.N == r.N && dense.status == "ok" && is_dense_row(dense.solver) && &dense != &r &&
          !is_classic(r.solver)) {
        const MatchedErrors m =
            errors_against(r.multipliers, dense.multipliers, std::vector<double>(dense.multipliers.size(), 0));
        double dev = 0;
        for (size_t k = 0; k < m.matched.size(); ++k)
          dev = std::max(dev, std::abs(m.matched[k] - dense.multipliers[k]));
        r.deviation_from_dense = dev / std::abs(dense.multipliers[0]);
        break;
      }
  }
}

void write_bench_csv(const Invocation& inv, const std::filesystem::path& path, const std::string& metadata_header,
                     const BenchSettings& s, const std::vector<BenchRow>& rows, const BenchReference& reference) {
  OutputFile csv(inv, path);
  csv.stream() << metadata_header;
  csv.stream() << "# delayspec bench: model " << s.problem.model_label << ", nev " << s.base.nev << ", reference "
               << reference.used << "\nN,n,solver,status,seconds,setup_seconds,peak_bytes,operator_applications,"
               << "error,max_error,correct_digits,deviation_from_dense,abs_mu1,abs_error,seconds_slowest\n";
  csv.stream().precision(10);
  for (const auto& r : rows)
    csv.stream() << r.N << "," << r.n << "," << r.solver << "," << r.status << "," << r.seconds << ","
                 << r.setup_seconds << "," << r.peak_bytes << "," << r.operator_applications << "," << r.error << ","
                 << r.max_error << "," << r.correct_digits << "," << r.deviation_from_dense << ","
                 << (r.multipliers.empty() ? NAN : std::abs(r.multipliers[0])) << "," << r.abs_error << ","
                 << r.seconds_slowest << "\n";
  csv.commit();
}

nlohmann::json bench_json(const BenchSettings& s, const std::vector<BenchRow>& rows, const BenchReference& reference) {
  nlohmann::json j;
  j["model"] = s.problem.model_name;
  j["events"] = to_string(s.problem.events);
  j["nev"] = s.base.nev;
  j["reference"] = reference.used;
  if (reference.used == "exact") j["reference_source"] = s.exact_source;  // lambert_w or spectral
  j["reference_values"] = multipliers_json(reference.values);
  if (!reference.note.empty()) j["reference_note"] = reference.note;
  j["dense_memory_limit_mb"] = s.limit_mb;
  j["peak_bytes_method"] = "VmHWM - VmRSS after malloc_trim and a reset of the peak mark (per row)";
  j["rows"] = nlohmann::json::array();
  for (const auto& r : rows) {
    nlohmann::json row = {{"N", r.N},
                          {"dimension", r.n},
                          {"solver", r.solver},
                          {"status", r.status},
                          {"seconds", number_or_null(r.seconds)},
                          {"seconds_slowest", number_or_null(r.seconds_slowest)},
                          {"setup_seconds", number_or_null(r.setup_seconds)},
                          {"peak_bytes", r.peak_bytes >= 0 ? nlohmann::json(r.peak_bytes) : nlohmann::json(nullptr)},
                          {"error", number_or_null(r.error)},
                          {"max_error", number_or_null(r.max_error)},
                          {"correct_digits", number_or_null(r.correct_digits)},
                          {"deviation_from_dense", number_or_null(r.deviation_from_dense)},
                          {"abs_error", number_or_null(r.abs_error)},
                          {"operator_applications", r.operator_applications},
                          {"repeats", r.repeats},
                          {"multipliers", multipliers_json(r.multipliers)}};
    if (!r.message.empty()) row["message"] = r.message;
    j["rows"].push_back(row);
  }
  return j;
}

void print_bench(std::ostream& out, const BenchSettings& s, const std::vector<BenchRow>& rows,
                 const BenchReference& reference) {
  char line[300];
  out << "delayspec bench: model " << s.problem.model_label << ", nev " << s.base.nev << ", reference "
      << reference.used << (reference.used == "exact" ? " (" + s.exact_source + ")" : "")
      << (reference.note.empty() ? "" : " (" + reference.note + ")") << "\n";
  std::snprintf(line, sizeof line, "  %6s  %7s  %-12s  %10s  %10s  %9s  %10s  %10s  %6s  %10s\n", "N", "n", "solver",
                "seconds", "peak MB", "op.appl", "error", "max error", "digits", "vs dense");
  out << line;
  for (const auto& r : rows) {
    if (r.status != "ok") {
      std::snprintf(line, sizeof line, "  %6d  %7ld  %-12s  %s: %s\n", r.N, r.n, r.solver.c_str(), r.status.c_str(),
                    r.message.c_str());
      out << line;
      continue;
    }
    std::snprintf(line, sizeof line, "  %6d  %7ld  %-12s  %10.4g  %10.3g  %9ld  %10.3e  %10.3e  %6.2f  %10.2e\n", r.N,
                  r.n, r.solver.c_str(), r.seconds, r.peak_bytes / (1024.0 * 1024.0), r.operator_applications, r.error,
                  r.max_error, r.correct_digits, r.deviation_from_dense);
    out << line;
  }
  // Speed-up of each Krylov solver over dense LAPACK at the same N.
  for (const auto& dense : rows) {
    if (dense.solver != "dense-lapack" || dense.status != "ok") continue;
    for (const auto& r : rows)
      if (r.N == dense.N && r.status == "ok" && !is_classic(r.solver) && !is_dense_row(r.solver)) {
        std::snprintf(line, sizeof line, "  N = %d: %s is %.0fx faster than dense-lapack\n", r.N, r.solver.c_str(),
                      dense.seconds / r.seconds);
        out << line;
      }
  }
  out << "peak MB: resident memory the solve added at its peak (VmHWM after a reset, per row)\n";
}

}  // namespace

int command_bench(Config& config, const Invocation& inv) {
  const auto command_start = std::chrono::steady_clock::now();
  const BenchSettings settings = read_bench_settings(config);  // read and check
  std::vector<BenchRow> rows = run_bench(settings, inv);       // compute
  const BenchReference reference = bench_reference(settings, rows);
  score_rows(rows, reference);
  const nlohmann::json j = bench_json(settings, rows, reference);
  if (inv.out_dir) {  // report: bench.csv, and bench.json, which `plot` draws the speed figure from
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - command_start).count();
    const OutputMetadata metadata = make_metadata("bench", inv.scene, config, j, seconds);
    const std::filesystem::path dir(*inv.out_dir);
    write_bench_csv(inv, dir / "bench.csv", metadata_comment_lines(metadata), settings, rows, reference);
    nlohmann::json file = j;
    file["metadata"] = metadata_json(metadata);
    write_output(inv, dir / "bench.json", file.dump(2) + "\n");
  }
  if (inv.json) inv.out << j.dump(2) << "\n";
  else print_bench(inv.out, settings, rows, reference);
  return 0;
}

}  // namespace delayspec::cli
