// delayspec converge: h-convergence study of the leading Floquet multipliers (CLI contract,
// design.md 1.8). Library part: include/delayspec/convergence.hpp.
//
// Keys: Ns (comma list) or N_min/N_max (doubling); nev, solver (default auto), ncv, tol,
// max_restarts, seed (floquet_settings.hpp); reference = exact | extrapolated |
// finest | auto; solver; extrapolation_order, extrapolation_order_step, extrapolation_levels;
// converge_target (a relative error: keep doubling N until every tracked multiplier's estimate
// meets it), converge_max_N, converge_max_seconds (its limits); events (a comma list: for the
// impact model `on,off` by default, side by side); the problem's and the orbit's keys.
//
// A level whose orbit cannot be found (simulation does not settle: e.g. an orbit that is
// spuriously unstable at a coarse N) is retried with Newton from the orbit of the nearest level
// that succeeded, prolonged to its N (delayspec/resolution_study.hpp); a level that still fails is a row with
// its reason (`failure`), not the end of the study (convergence.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include "scene/output/output_directory.hpp"
#include "scene/commands/commands.hpp"
#include "delayspec/convergence.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/floquet.hpp"
#include "scene/problem/autonomous_floquet.hpp"
#include "scene/problem/floquet_settings.hpp"
#include "scene/problem/level_runner.hpp"
#include "scene/output/metadata.hpp"
#include "scene/output/output.hpp"
#include "scene/problem/problem.hpp"
#include "scene/output/progress.hpp"

namespace delayspec::cli {

namespace {

// What ended a study, in the keys' words (the JSON's stopped_by): the list `Ns`, the target, the
// key that bounded it, a failure.
std::string stop_key(StudyStop stop) {
  switch (stop) {
    case StudyStop::levels: return "Ns";
    case StudyStop::target: return "target";
    case StudyStop::max_N: return "converge_max_N";
    case StudyStop::max_seconds: return "converge_max_seconds";
    case StudyStop::failure: return "failure";
  }
  return "?";
}

// A failure message on one line (for a CSV comment).
std::string one_line(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  return text;
}

nlohmann::json study_json(const ConvergenceStudy& s, const std::string& events, const std::string& source) {
  nlohmann::json j;
  j["events"] = events;
  j["reference"] = to_string(s.reference);
  if (s.reference == ReferenceKind::exact) j["reference_source"] = source;  // lambert_w or spectral (level_runner.hpp)
  j["reference_values"] = multipliers_json(s.reference_values);
  j["reference_precision"] = s.reference_precision;
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& r : s.rows) {
    nlohmann::json row;
    row["N"] = r.N;
    if (!r.failure.empty()) row["failure"] = r.failure;  // then multipliers [] and error null
    if (!r.note.empty()) row["note"] = r.note;
    row["multipliers"] = multipliers_json(r.multipliers);
    row["error"] = number_or_null(r.error);
    row["errors"] = nlohmann::json::array();
    for (double e : r.errors) row["errors"].push_back(number_or_null(e));
    row["correct_digits"] = r.correct_digits;
    row["seconds"] = r.seconds;
    row["operator_applications"] = r.operator_applications;
    rows.push_back(row);
  }
  j["rows"] = rows;
  j["observed_order"] = s.order.observed ? nlohmann::json(*s.order.observed) : nlohmann::json(nullptr);
  j["order_settled"] = s.order.settled;
  j["order_basis"] = s.order.basis;
  j["order_note"] = s.order.note;
  j["least_squares_order"] = number_or_null(s.order.least_squares);
  nlohmann::json pairs = nlohmann::json::array();
  for (size_t i = 0; i < s.order.pair_orders.size(); ++i)
    pairs.push_back({{"N", s.order.pair_N[i]}, {"order", number_or_null(s.order.pair_orders[i])}});
  j["pair_orders"] = pairs;
  nlohmann::json tracks = nlohmann::json::array();
  for (const auto& t : s.track_orders)
    tracks.push_back(t.observed ? nlohmann::json(*t.observed) : nlohmann::json(nullptr));
  j["track_orders"] = tracks;
  nlohmann::json ex = nlohmann::json::array();
  for (const auto& e : s.extrapolated)
    ex.push_back({{"re", e.value.real()},
                  {"im", e.value.imag()},
                  {"abs", std::abs(e.value)},
                  {"error_estimate", number_or_null(e.error_estimate)},  // null: no estimate possible
                  {"levels", e.levels},
                  {"note", e.note}});
  j["extrapolated"] = ex;
  nlohmann::json cols = nlohmann::json::array();
  for (size_t c = 0; c < s.richardson.columns.size(); ++c) {
    nlohmann::json col;
    col["levels"] = c + 1;
    col["expected_order"] = s.richardson.expected_orders[c];
    col["observed_order"] =
        s.richardson.column_orders[c] ? nlohmann::json(*s.richardson.column_orders[c]) : nlohmann::json(nullptr);
    if (c < s.richardson.difference_orders.size()) {
      col["difference_order"] = number_or_null(s.richardson.difference_orders[c]);
      col["consistent"] =
          s.richardson.consistent[c] < 0 ? nlohmann::json(nullptr) : nlohmann::json(s.richardson.consistent[c] == 1);
      col["used"] = static_cast<int>(c) + 1 == s.richardson.levels_used;
    }
    nlohmann::json entries = nlohmann::json::array();
    for (size_t i = 0; i < s.richardson.columns[c].size(); ++i) {
      const auto v = s.richardson.columns[c][i];
      entries.push_back({{"N", s.richardson.Ns[i + c]},
                         {"re", v.real()},
                         {"im", v.imag()},
                         {"abs", std::abs(v)},
                         {"error", number_or_null(s.richardson.errors[c][i])}});
    }
    col["entries"] = entries;
    cols.push_back(col);
  }
  j["richardson"] = cols;
  j["seconds"] = s.seconds;
  j["target_met"] = s.target_met ? nlohmann::json(*s.target_met) : nlohmann::json(nullptr);
  j["stopped_by"] = stop_key(s.stopped_by);
  if (!s.stop_note.empty()) j["stop_note"] = s.stop_note;
  return j;
}

void print_study(std::ostream& out, const ConvergenceStudy& s, const std::string& events, bool switching,
                 const std::string& source) {
  char line[256];
  if (switching) out << "\nevents = " << events << "\n";
  out << "reference: " << to_string(s.reference) << (s.reference == ReferenceKind::exact ? " (" + source + ")" : "")
      << " (relative precision " << s.reference_precision[0] << ")\n";
  std::snprintf(line, sizeof line, "  %6s  %10s  %8s  %20s  %10s  %6s  %6s\n", "N", "seconds", "op.appl", "|mu_1|",
                "error", "digits", "order");
  out << line;
  for (size_t i = 0; i < s.rows.size(); ++i) {
    const auto& r = s.rows[i];
    if (!r.failure.empty()) {
      std::snprintf(line, sizeof line, "  %6d  %10.4f  failed: ", r.N, r.seconds);
      out << line << r.failure << "\n";
      continue;
    }
    std::string order = "";
    for (size_t k = 0; k < s.order.pair_N.size(); ++k)
      if (s.order.pair_N[k] == r.N) {
        std::snprintf(line, sizeof line, "%.3f", s.order.pair_orders[k]);
        order = line;
      }
    std::snprintf(line, sizeof line, "  %6d  %10.4f  %8ld  %20.15f  %10.3e  %6.2f  %6s\n", r.N, r.seconds,
                  r.operator_applications, std::abs(r.multipliers[0]), r.error, r.correct_digits[0], order.c_str());
    out << line;
  }
  for (const auto& r : s.rows)
    if (r.failure.empty() && !r.note.empty()) out << "  N = " << r.N << ": " << r.note << "\n";
  out << "observed order (" << s.order.basis << " based): ";
  if (s.order.observed) {
    std::snprintf(line, sizeof line, "%.3f", *s.order.observed);
    out << line << (s.order.settled ? " (settled)" : "");
  } else {
    out << "none";
  }
  std::snprintf(line, sizeof line, "; least-squares slope over all levels %.3f", s.order.least_squares);
  out << line << "\n";
  if (!s.order.note.empty()) out << "note: " << s.order.note << "\n";
  if (!s.extrapolated.empty()) {
    out << "extrapolated multipliers (Richardson):\n";
    for (size_t k = 0; k < s.extrapolated.size(); ++k) {
      const auto& e = s.extrapolated[k];
      std::snprintf(line, sizeof line, "  %3zu  %22.15e  %22.15e  |mu| %18.15f  +- %.1e (%d levels)\n", k + 1,
                    e.value.real(), e.value.imag(), std::abs(e.value), e.error_estimate, e.levels);
      out << line;
    }
    out << "  (mu_1: " << s.extrapolated[0].note << ")\n";
  }
  if (s.richardson.columns.size() > 1) {
    out << "Richardson columns of mu_1 (relative error against the reference):\n  " << std::string(6, ' ');
    for (size_t c = 0; c < s.richardson.columns.size(); ++c) {
      std::snprintf(line, sizeof line, "  %10s", (std::to_string(c + 1) + " level" + (c ? "s" : "")).c_str());
      out << line;
    }
    out << "\n";
    for (size_t i = 0; i < s.richardson.Ns.size(); ++i) {
      std::snprintf(line, sizeof line, "  %6d", s.richardson.Ns[i]);
      out << line;
      for (size_t c = 0; c < s.richardson.columns.size(); ++c) {
        if (i < c) {
          std::snprintf(line, sizeof line, "  %10s", "");
        } else {
          const double e = s.richardson.errors[c][i - c];
          if (std::isfinite(e)) std::snprintf(line, sizeof line, "  %10.3e", e);
          else std::snprintf(line, sizeof line, "  %10s", "(ref)");
        }
        out << line;
      }
      out << "\n";
    }
    out << "  order ";
    for (size_t c = 0; c < s.richardson.columns.size(); ++c) {
      if (s.richardson.column_orders[c]) std::snprintf(line, sizeof line, "  %10.2f", *s.richardson.column_orders[c]);
      else std::snprintf(line, sizeof line, "  %10s", "-");
      out << line;
    }
    out << "\n  expect";
    for (size_t c = 0; c < s.richardson.columns.size(); ++c) {
      std::snprintf(line, sizeof line, "  %10.0f", s.richardson.expected_orders[c]);
      out << line;
    }
    // reference-free: order of each column's last three entries, and the verdict it gives
    out << "\n  diff. ";
    for (size_t c = 0; c < s.richardson.difference_orders.size(); ++c) {
      const double p = s.richardson.difference_orders[c];
      const int ok = s.richardson.consistent[c];
      if (std::isfinite(p)) std::snprintf(line, sizeof line, "  %8.2f %s", p, ok == 1 ? "+" : ok == 0 ? "x" : " ");
      else std::snprintf(line, sizeof line, "  %10s", "-");
      out << line;
    }
    out << "\n  (order: least squares against the reference; diff.: from the last differences of the column, + consistent"
           " with the expected order, x not; columns after the first that is not + are not used)\n";
  }
  if (!s.stop_note.empty()) out << "stopped: " << s.stop_note << "\n";
}

// The period of an orbit of unknown period at each level, and extrapolated.
void print_period_study(std::ostream& out, const PeriodStudy& p) {
  char line[200];
  out << "period of the orbit (unknown, found with it; the multipliers below are the others, the trivial one "
         "apart):\n";
  for (size_t i = 0; i < p.Ns.size(); ++i) {
    std::snprintf(line, sizeof line, "  N = %6d  (K = %7d)  T = %.15g\n", p.Ns[i], p.Ks[i], p.periods[i]);
    out << line;
  }
  if (p.extrapolated) {
    std::snprintf(line, sizeof line, "  extrapolated T = %.15g +- %.1e\n", p.extrapolated->value.real(),
                  p.extrapolated->error_estimate);
    out << line << "  (" << p.extrapolated->note << ")\n";
  }
}

// What the command reads and checks before any work; the keys are read in this order (--help lists them so).
struct ConvergeSettings {
  std::vector<std::string> events;  // the variants, side by side; the problem has the first
  Problem problem;
  bool switching = false;
  OrbitSettings orbit_settings;
  ConvergenceOptions base;  // the options of every variant but the Richardson orders
  FloquetOptions solver_options;
  bool order_given = false, step_given = false;  // else each variant's own expansion (error_expansion)
  double x_order = 2, x_step = 2;
  std::optional<double> period_guess;  // an autonomous orbit of unknown period (autonomous_floquet.hpp)
  std::string reference_source;        // of the exact reference: lambert_w, spectral (exact_reference)
};

// Reads and checks the keys, the levels and the reference (the exact multipliers where a model has them).
ConvergeSettings read_converge_settings(Config& config) {
  ConvergeSettings s;
  // events may be a list here (side by side); the problem reads the first of them.
  // Models that switch (the impact wall, milling's cutting windows): located and not, side by side.
  // Whether the model switches is the model's own (its analyses); `events` is read after it.
  use_first_level_as_N(config);
  Config first = config;
  first.set("events", "on", "converge");
  const bool switching_default = read_problem(first, 100).switching();
  s.events = read_word_list(config, "events", switching_default ? "on,off" : "on", event_mode_names());
  config.set("events", s.events.front(), "converge");
  s.problem = read_problem(config, 100);
  s.switching = s.problem.switching();
  s.orbit_settings = read_orbit_settings(config);
  ConvergenceOptions& base = s.base;
  base.Ns = read_N_list(config, s.problem, 25, 400);
  s.solver_options = read_floquet_options(config, 2);  // nev, solver, ncv, tol, ...
  base.nev = s.solver_options.nev;
  base.extra = std::max(2, base.nev / 2);
  base.reference = read_reference_kind(config);
  s.order_given = config.has("extrapolation_order");
  s.step_given = config.has("extrapolation_order_step");
  s.x_order = config.get_double("extrapolation_order", 2);
  s.x_step = config.get_double("extrapolation_order_step", 2);
  require_positive("extrapolation_order", s.x_order);
  require_positive("extrapolation_order_step", s.x_step);
  // More columns than levels is harmless (the table stops at the levels); the bound keeps the cast exact.
  // 6 (was 4 until issue 58): on an aligned grid the expansion is even and each column is used
  // only where the one below shows its order, so more columns cost nothing where they do not
  // apply and gain where they do (milling a/D = 1: 1.2e-11 with 4, 2.2e-12 with 6 from the same
  // solves, issue 58)
  base.richardson.max_columns = static_cast<int>(config.get_int_in_range("extrapolation_levels", 6, 1, 1000));
  base.target = config.get_double("converge_target", 0);
  base.max_N = static_cast<int>(config.get_int_in_range("converge_max_N", base.max_N, 1, 10'000'000));
  base.max_seconds = config.get_double("converge_max_seconds", base.max_seconds);
  if (!config.has("converge_target"))
    for (const char* key : {"converge_max_N", "converge_max_seconds"})
      if (config.has(key))
        throw BadInput("`" + std::string(key) + " = " + config.get_string(key, "") +
                       "`: a limit of `converge_target`, which is not given");
  s.period_guess = read_period_guess(config, s.problem);
  if (config.has("converge_target") && !(base.target > 0))
    throw BadInput("`converge_target = " + config.get_string("converge_target", "") + "`: must be > 0");
  if (!(base.max_seconds > 0) || !std::isfinite(base.max_seconds) || base.max_seconds > 1e7)
    throw BadInput("`converge_max_seconds = " + config.get_string("converge_max_seconds", "") +
                   "`: must be > 0 and at most 1e7");
  config.check_all_used();

  Problem coarsest = s.problem;
  coarsest.N = base.Ns.front();
  const long n_min = coarsest.dimension();
  validate_floquet_options(s.solver_options, n_min);  // at the coarsest N, the smallest n
  if (!s.period_guess) {
    const ExactReference exact = exact_reference(s.problem, base.nev + base.extra);
    base.exact = exact.multipliers;
    base.exact_precision = exact.precision;
    s.reference_source = exact.source;
  }
  if (base.reference == ReferenceKind::exact && base.exact.empty())
    throw BadInput("`reference = exact`: model `" + s.problem.model_name +
                   "` has no exact multipliers (use extrapolated or finest)");
  return s;
}

// One convergence study per events variant, each with its own Richardson orders; with
// period_guess also the period's study (`period`).
std::vector<ConvergenceStudy> run_studies(const ConvergeSettings& s, const Invocation& inv, PeriodStudy& period) {
  std::vector<ConvergenceStudy> studies;
  Progress progress(inv.err, "converge", s.base.target > 0 ? 0 : static_cast<long>(s.base.Ns.size() * s.events.size()),
                    inv.quiet);
  for (const std::string& ev : s.events) {
    ConvergenceOptions options = s.base;
    Problem with_events = s.problem;
    with_events.events = parse_event_mode(ev);
    const RichardsonOptions expansion = error_expansion(with_events);  // h, h^2 with events = off
    options.richardson.order = s.order_given ? s.x_order : expansion.order;
    options.richardson.order_step = s.step_given ? s.x_step : expansion.order_step;
    options.richardson.leading_term_may_hide = expansion.leading_term_may_hide;
    if (s.period_guess) {  // each level's orbit and period from the guess; the trivial multiplier apart
      studies.push_back(run_convergence_study(
          [&](int N, int count) {
            LevelResult r;
            const auto start = std::chrono::steady_clock::now();
            try {
              FloquetOptions solver = s.solver_options;
              solver.nev = count;
              AutonomousFloquetLevel level = autonomous_level(*with_events.analyses, step_options(with_events), N,
                                                              *s.period_guess, s.orbit_settings, solver);
              period.add(N, level.orbit);
              r = std::move(level.others);
            } catch (const NumericalFailure& e) {
              r.failure = e.what();
            }
            r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            progress.add();
            return r;
          },
          options));
      period.extrapolate(options.richardson);
      continue;
    }
    ResolutionStudy levels = resolution_study(with_events, s.orbit_settings, s.solver_options, &progress);
    studies.push_back(
        run_convergence_study([&](int N, int count) { return levels.level(N, count); }, options,
                              [&](int N, int count, int from_N) { return levels.retry(N, count, from_N); }));
  }
  progress.finish();
  return studies;
}

// --out DIR: converge.csv (every level's multipliers) and converge_richardson.csv (mu_1's columns).
void write_converge_files(const Invocation& inv, const Config& config, const ConvergeSettings& s,
                          const std::vector<ConvergenceStudy>& studies, double seconds) {
  const std::filesystem::path dir(*inv.out_dir);
  const std::string header =
      metadata_comment_lines(make_metadata("converge", inv.scene, config, nlohmann::json::object(), seconds));
  OutputFile rows(inv, dir / "converge.csv");
  rows.stream() << header << "# delayspec converge: model " << s.problem.model_label << ", solver "
                << to_string(s.solver_options.solver) << "\n";
  for (size_t v = 0; v < studies.size(); ++v)  // failed levels have no multipliers: named here
    for (const auto& r : studies[v].rows)
      if (!r.failure.empty())
        rows.stream() << "# events " << s.events[v] << ", N = " << r.N << " failed: " << one_line(r.failure) << "\n";
  rows.stream() << "events,N,track,re,im,abs,error,correct_digits,seconds,operator_applications\n";
  rows.stream().precision(17);
  OutputFile rich(inv, dir / "converge_richardson.csv");
  rich.stream()
      << header
      << "# delayspec converge: Richardson columns of mu_1 (levels combined)\nevents,N,levels,re,im,abs,error\n";
  rich.stream().precision(17);
  for (size_t v = 0; v < studies.size(); ++v) {
    const auto& st = studies[v];
    const std::string& ev = s.events[v];
    for (const auto& r : st.rows)
      for (size_t k = 0; k < r.multipliers.size(); ++k)
        rows.stream() << ev << "," << r.N << "," << k + 1 << "," << r.multipliers[k].real() << ","
                      << r.multipliers[k].imag() << "," << std::abs(r.multipliers[k]) << "," << r.errors[k] << ","
                      << r.correct_digits[k] << "," << r.seconds << "," << r.operator_applications << "\n";
    for (size_t c = 0; c < st.richardson.columns.size(); ++c)
      for (size_t i = 0; i < st.richardson.columns[c].size(); ++i) {
        const auto x = st.richardson.columns[c][i];
        rich.stream() << ev << "," << st.richardson.Ns[i + c] << "," << c + 1 << "," << x.real() << "," << x.imag()
                      << "," << std::abs(x) << "," << st.richardson.errors[c][i] << "\n";
      }
  }
  rows.commit();
  rich.commit();
}

// The --json result: the first variant's study at the top level, every variant's under by_events.
nlohmann::json converge_json(const ConvergeSettings& s, const std::vector<ConvergenceStudy>& studies,
                            const PeriodStudy& period) {
  nlohmann::json j = study_json(studies.front(), s.events.front(), s.reference_source);
  if (s.period_guess) {
    j["period_guess"] = *s.period_guess;
    j["period"] = period_study_json(period);
  }
  j["model"] = s.problem.model_name;
  j["solver"] = to_string(s.solver_options.solver);
  j["nev"] = s.base.nev;
  if (studies.size() > 1) {
    j["by_events"] = nlohmann::json::array();
    for (size_t v = 0; v < studies.size(); ++v)
      j["by_events"].push_back(study_json(studies[v], s.events[v], s.reference_source));
    // The top level's target_met is every variant's: it said true while the events = off study
    // missed the target (issue 61 item 9); target_note names the ones that missed it.
    std::string missed;
    for (size_t v = 0; v < studies.size(); ++v)
      if (studies[v].target_met && !*studies[v].target_met)
        missed += (missed.empty() ? "" : "; ") + std::string("events = ") + s.events[v] + ": not met (" +
                  stop_key(studies[v].stopped_by) + ")";
    if (!missed.empty()) {
      j["target_met"] = false;
      j["target_note"] = missed;
    }
  }
  return j;
}

// The variants side by side: mu_1's relative error at every N any of them reached.
void print_side_by_side(std::ostream& out, const std::vector<ConvergenceStudy>& studies,
                        const std::vector<std::string>& events) {
  char line[200];
  out << "\nside by side: relative error of mu_1 (correct digits)\n  " << std::string(6, ' ');
  for (const auto& ev : events) {
    std::snprintf(line, sizeof line, "  %22s", ("events = " + ev).c_str());
    out << line;
  }
  out << "\n";
  std::set<int> all_N;  // with a target the variants may end at different N
  for (const auto& s : studies)
    for (const auto& r : s.rows) all_N.insert(r.N);
  for (int N : all_N) {
    std::snprintf(line, sizeof line, "  %6d", N);
    out << line;
    for (const auto& s : studies) {
      const auto r = std::find_if(s.rows.begin(), s.rows.end(), [&](const ConvergenceRow& x) { return x.N == N; });
      if (r == s.rows.end()) std::snprintf(line, sizeof line, "  %22s", "-");
      else if (!r->failure.empty()) std::snprintf(line, sizeof line, "  %22s", "failed");
      else std::snprintf(line, sizeof line, "  %13.3e (%5.2f)", r->error, r->correct_digits[0]);
      out << line;
    }
    out << "\n";
  }
}

}  // namespace

int command_converge(Config& config, const Invocation& inv) {
  const auto command_start = std::chrono::steady_clock::now();
  const ConvergeSettings s = read_converge_settings(config);
  PeriodStudy period;
  const std::vector<ConvergenceStudy> studies = run_studies(s, inv, period);
  if (inv.out_dir)
    write_converge_files(inv, config, s, studies,
                         std::chrono::duration<double>(std::chrono::steady_clock::now() - command_start).count());
  if (inv.json) {
    inv.out << converge_json(s, studies, period).dump(2) << "\n";
    return 0;
  }
  inv.out << "delayspec converge: model " << s.problem.model_label << ", solver " << to_string(s.solver_options.solver)
          << ", nev " << s.base.nev << ", N = ";
  for (size_t i = 0; i < s.base.Ns.size(); ++i) inv.out << (i ? "," : "") << s.base.Ns[i];
  inv.out << "\n";
  if (s.period_guess) print_period_study(inv.out, period);
  for (size_t v = 0; v < studies.size(); ++v) print_study(inv.out, studies[v], s.events[v], s.switching, s.reference_source);
  if (studies.size() > 1) print_side_by_side(inv.out, studies, s.events);
  return 0;
}

}  // namespace delayspec::cli
