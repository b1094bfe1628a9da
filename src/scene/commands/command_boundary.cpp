// delayspec boundary: a stability boundary as a curve in two model keys, each point with its
// distance to the N -> infinity curve (issue 36; boundary.hpp; docs/continuation.md,
// "Stability boundaries as curves").
//
// The start: `continue` in boundary_y over [boundary_y_from, boundary_y_to] at x = boundary_x_from
// (the finest N) locates the bifurcations there; the first of boundary_type (any: the first of
// any type but grazing) starts the curve. A grazing curve's test function is the orbit's max H
// (orbit_contacts: over the steps' interpolants), zero where the orbit touches the switching
// surface. With boundary_starts = scan, the same search at boundary_scan_points values of x
// gives a start at each, and every start not on a curve already followed starts another
// (followed both ways from it): the lobes of a lobe diagram. A curve is followed at the finest N
// (trace_boundary_both_ways), the test function at each (x, y) evaluated on the orbit solved
// there (linear models: the zero orbit; nonlinear: at least one Newton step from the last orbit,
// the scene's orbit search where that fails). With boundary_Ns, each point is studied against the coarser N's curves
// (boundary_point_study): `x_extrapolated`, `y_extrapolated` and their error estimates.
//
// Files with --out DIR: boundary.csv (metadata header; one row per point: curve, x, y, angle,
// the extrapolations and their estimates, x and y at each N; nan where there is none) and
// boundary.json (the --json result).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>

#include <nlohmann/json.hpp>

#include "delayspec/boundary.hpp"
#include "delayspec/richardson.hpp"
#include "scene/commands/boundary_equilibria.hpp"
#include "scene/commands/commands.hpp"
#include "scene/output/metadata.hpp"
#include "scene/output/output.hpp"
#include "scene/output/output_directory.hpp"
#include "scene/output/progress.hpp"
#include "scene/points/parallel_points.hpp"
#include "scene/problem/boundary_settings.hpp"
#include "scene/problem/continue_settings.hpp"
#include "scene/problem/floquet_settings.hpp"
#include "scene/problem/orbit_settings.hpp"
#include "scene/problem/parameter_grid.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

namespace {

using nlohmann::json;

struct BoundaryRun {
  std::string x_key, y_key;
  BoundaryOptions options;
  std::optional<BifurcationType> type;  // none: any (the first found at x_from)
  std::vector<int> Ns;                  // boundary_Ns, or the one level N
  std::vector<int> finer_Ns;            // boundary_refine: 2 and 4 Ns.back(), studied where Ns are pre-asymptotic
  int scan_points = 0;                  // boundary_starts = scan: the x values searched; 0: the first start only
  int threads = 1;                      // for the error bars (study_points)
  OrbitSettings orbit_settings;
  FloquetOptions floquet;
  Problem problem;  // at (x_from, y_from)
  int x_index = -1, y_index = -1;  // the keys' parameters in problem.family
  // The problem at (x, y) and resolution N (its family's model, no scene read); nothing, with
  // the model's reason in `rejected`, where the model refuses them.
  std::optional<Problem> at(double x, double y, int N, std::string& rejected) const {
    const std::vector<double> values =
        ProblemFamily::with(ProblemFamily::with(problem.parameter_values, x_index, x), y_index, y);
    return problem_at(problem, values, N, rejected);
  }
};

BoundaryRun read_boundary_run(Config& config) {
  BoundaryRun run;
  const BoundarySettings settings = read_boundary_settings(config);
  run.x_key = settings.x_key;
  run.y_key = settings.y_key;
  run.options = settings.options;
  run.scan_points = settings.scan_points;
  const BoundaryOptions& o = run.options;
  const std::string type = config.get_choice("boundary_type", "any",
                                             {"any", "neimark-sacker", "period-doubling", "fold", "grazing"});
  for (BifurcationType t : {BifurcationType::neimark_sacker, BifurcationType::period_doubling, BifurcationType::fold,
                            BifurcationType::grazing})
    if (type == to_string(t)) run.type = t;
  for (long N : config.get_int_list("boundary_Ns", {})) {
    if (N < 1 || N > 10'000'000) throw BadInput("`boundary_Ns`: N = " + std::to_string(N) + " must be between 1 and 1e7");
    if (!run.Ns.empty() && N <= run.Ns.back())
      throw BadInput("`boundary_Ns`: must be increasing (" + std::to_string(run.Ns.back()) + ", " + std::to_string(N) + ")");
    run.Ns.push_back(static_cast<int>(N));
  }
  const bool refine = config.get_choice("boundary_refine", "on", {"on", "off"}) == "on";
  run.threads = read_threads(config);
  run.orbit_settings = read_orbit_settings(config);
  run.floquet = read_floquet_options(config);
  run.problem = starting_problem(read_problem(config, 100), config,
                                 {{"boundary_x", run.x_key, o.x_from, "boundary_x_from"},
                                  {"boundary_y", run.y_key, o.y_from, "boundary_y_from"}});
  run.x_index = family_parameter(run.problem, "boundary_x", run.x_key);
  run.y_index = family_parameter(run.problem, "boundary_y", run.y_key);
  if (run.type == BifurcationType::grazing && !run.problem.analyses->switches_in_state())
    throw BadInput("`boundary_type = grazing`: model " + run.problem.model_name +
                   " has no switching surface H(y) = 0 for its orbit to graze");
  config.check_all_used();
  if (run.Ns.empty()) run.Ns = {run.problem.N};
  if (refine && run.Ns.size() >= 3)  // (with two, the refined levels are two)
    run.finer_Ns = {2 * run.Ns.back(), 4 * run.Ns.back()};
  return run;
}

// The test function of `type` at (x, y) at one N: the model at both values, its orbit and
// leading multipliers. A nonlinear model's orbit is found by Newton from the last one found.
// at_point: at a point of the traced curve, whose sample also carries where it meets a curve of
// the other kind (boundary.hpp's at_points): on a grazing curve this needs the multipliers too.
class TestFunctionAt {
 public:
  TestFunctionAt(const BoundaryRun& run, BifurcationType type, int N)
      : run_(run), type_(type), N_(N), orbit_settings_(run.orbit_settings) {
    // From the last point's orbit: one Newton step even when it meets the tolerance (orbit_newton.hpp)
    orbit_settings_.newton.min_iterations = 1;
  }
  BoundarySample operator()(double x, double y) const { return evaluate(x, y, false); }
  BoundarySample at_point(double x, double y) const { return evaluate(x, y, true); }

 private:
  BoundarySample evaluate(double x, double y, bool on_curve) const {
    std::string rejected;
    const std::optional<Problem> p = run_.at(x, y, N_, rejected);
    if (!p) return undefined(rejected);  // a value the model refuses
    try {
      if (last_orbit_.size() > 0) {
        try {
          return sample(*p, &last_orbit_, on_curve);
        } catch (const NumericalFailure&) {  // Newton from the last orbit: the search from scratch below
        }
      }
      return sample(*p, nullptr, on_curve);
    } catch (const BadInput& e) {  // an analysis that refuses this point
      return undefined(e.what());
    } catch (const NumericalFailure& e) {  // an orbit or an eigensolver that fails
      return undefined(e.what());
    }
  }

  // The test function on the orbit found by Newton from `guess` (the last orbit found), or
  // (nullptr) by the orbit search of the scene's settings.
  BoundarySample sample(const Problem& p, const Eigen::VectorXd* guess, bool on_curve) const {
    OrbitRequest request;
    request.sequence = !p.analyses->is_linear();
    request.newton_guess = guess;
    request.align_contacts = false;  // as the curve's branches are continued (model_analyses.hpp)
    // A grazing curve: the orbit of the field below the surface (step_options.hpp's
    // fixed_region), smooth where the switched orbit starts to touch; the same orbit where max H <= 0.
    MapSettings map = p.map_settings();
    const bool grazing = type_ == BifurcationType::grazing;
    if (grazing) map.step.fixed_region = 2;
    const LinearisedOrbit at = p.analyses->linearised_orbit(map, orbit_settings_, request);
    // Grazing: max H, and at a point of the curve the multipliers, where the eigensolver converges
    // (a failure there only hides where the curve meets a stability curve).
    FloquetResult r;
    if (!grazing) {
      r = floquet_multipliers(*at.monodromy, run_.floquet);
    } else if (on_curve) {
      try {
        r = floquet_multipliers(*at.monodromy, run_.floquet);
      } catch (const NumericalFailure&) {
      }
    }
    if (at.sequence.size() > 0) last_orbit_ = at.sequence;
    return boundary_sample(type_, r.multipliers, at.contacts.max_H);
  }
  static BoundarySample undefined(const std::string& reason) {
    BoundarySample s;
    s.reason = reason;
    return s;
  }
  // An object serves one thread, as its last orbit does.
  const BoundaryRun& run_;
  BifurcationType type_;
  int N_;
  OrbitSettings orbit_settings_;
  mutable Eigen::VectorXd last_orbit_;
};

// A curve's start: a bifurcation `continue` located in y at x (the finest N).
struct Start {
  BifurcationType type;
  double x, y;
};

// The bifurcations in y at x of the wanted type (any: every type but grazing, which bounds no
// stability region), in the order of y from y_from, and whether the orbit is stable at y_from;
// `found` lists all it located.
struct Search {
  std::vector<Start> starts;
  bool stable_at_y_from = false;
  std::string found, failure;
};
Search search_at(const BoundaryRun& run, double x, int N) {
  std::string rejected;
  const std::optional<Problem> at_x = run.at(x, run.options.y_from, N, rejected);
  if (!at_x) throw BadInput(rejected);
  const Problem& problem = *at_x;
  ContinuationOptions search;
  search.from = run.options.y_from;
  search.to = run.options.y_to;
  search.tolerance = run.options.tolerance * std::abs(run.options.y_to - run.options.y_from);
  search.N = N;
  search.periods_per_map = problem.orbit_period;
  search.step_options = step_options(problem);
  search.floquet = run.floquet;
  search.newton.tolerance = run.orbit_settings.newton.tolerance;
  search.start_iterations = run.orbit_settings.newton.max_iterations;
  const ContinuationResult branch =
      problem.analyses->continue_orbit(analyses_along(problem, run.y_index), run.orbit_settings, search);
  Search out;
  out.stable_at_y_from = !branch.points.empty() && branch.points.front().stable();
  out.failure = branch.failure;
  for (const Bifurcation& b : branch.bifurcations) {
    out.found += (out.found.empty() ? "" : ", ") + to_string(b.type) + " at " + format_number(b.parameter);
    if (run.type ? *run.type == b.type : b.type != BifurcationType::grazing)
      out.starts.push_back({b.type, x, b.parameter});
  }
  return out;
}

// A start found at a coarser N moved to the finest: y at the same x where the finest N's test
// function of the start's type vanishes, by the secant from the coarser y (boundary_offset_along
// in y). Nothing when that finds no root within 10 % of the y range (on milling_lobes_curves.toml
// N = 100 and 400 differ by up to 4.7 % at fixed speed: a lobe's side is steep, and the levels'
// lobes lie apart in speed). Whatever root it finds is a point of a curve of that type at the
// finest N: the curve's start checks it (trace_boundary), the scan skips it when it is on a
// curve already followed.
std::optional<Start> at_finest_N(const BoundaryRun& run, const Start& coarse) {
  const TestFunctionAt g(run, coarse.type, run.Ns.back());
  const double range = run.options.y_to - run.options.y_from;
  const double s = boundary_offset_along(std::cref(g), coarse.x, coarse.y, 0, range, 1e-6, run.options.tolerance);
  if (!(std::abs(s) <= 0.1)) return std::nullopt;
  return Start{coarse.type, coarse.x, coarse.y + s * range};
}

// The first start in y at x: searched by `continue` at the coarsest N of boundary_Ns and moved to
// the finest (at_finest_N): on milling_lobes_curves.toml the 40 starts' search took 0.26 s instead
// of 0.36-0.44 at N = 400 (a `continue` at N = 100 costs half one at 400: its fixed costs
// dominate). Searched at the finest N where the coarsest finds none or the move fails.
Search first_start_at(const BoundaryRun& run, double x) {
  if (run.Ns.size() > 1) {
    try {
      Search coarse = search_at(run, x, run.Ns.front());
      if (!coarse.starts.empty())
        if (const std::optional<Start> start = at_finest_N(run, coarse.starts.front())) {
          coarse.starts = {*start};
          return coarse;
        }
    } catch (const NumericalFailure&) {  // (the finest N's search below says what fails)
    }
  }
  return search_at(run, x, run.Ns.back());
}

// The starts of the curves: the first bifurcation of the type at x_from (boundary_starts = first),
// or (scan) the first one in y at each of scan_points values of x, less those on a curve already
// followed (`follow` is called for each start in turn). stable_below: the orbit is stable at y_from
// at every x searched (the side of the curves a chart would call stable). NumericalFailure when
// there is no start at all, with what was found.
template <class Follow>
bool follow_starts(const BoundaryRun& run, std::vector<BoundaryCurve>& curves,
                   std::vector<BifurcationType>& types, Follow follow) {
  const BoundaryOptions& o = run.options;
  const int count = run.scan_points > 0 ? run.scan_points : 1;
  const auto x_of = [&](long i) { return count == 1 ? o.x_from : o.x_from + (o.x_to - o.x_from) * i / (count - 1); };
  // The searches first, on `threads` threads (none depends on the curves), then the curves
  // followed in the order of x: the same curves for any thread count.
  std::vector<Search> searches(static_cast<size_t>(count));
  std::vector<std::string> failed(static_cast<size_t>(count));  // a search's NumericalFailure
  parallel_points(count, run.threads, [&](long i) {
    try {
      searches[static_cast<size_t>(i)] = first_start_at(run, x_of(i));
    } catch (const NumericalFailure& e) {  // (one x of a scan: the others may still start curves)
      if (count == 1) throw;
      failed[static_cast<size_t>(i)] = e.what();
    }
  });
  bool stable_below = true;
  std::string found;
  for (int i = 0; i < count; ++i) {
    const double x = x_of(i);
    const Search& search = searches[static_cast<size_t>(i)];
    if (!failed[static_cast<size_t>(i)].empty()) {
      found += (found.empty() ? "" : "; ") + run.x_key + " = " + format_number(x) + ": " + failed[static_cast<size_t>(i)];
      stable_below = false;
      continue;
    }
    stable_below = stable_below && search.stable_at_y_from;
    if (!search.found.empty())
      found += (found.empty() ? "" : "; ") + run.x_key + " = " + format_number(x) + ": " + search.found;
    if (search.starts.empty()) continue;
    const Start& start = search.starts.front();  // the first in y: where the orbit loses (or gains) stability
    if (on_boundary_curve(curves, start.x, start.y, 1e-3 * std::abs(o.y_to - o.y_from))) continue;
    curves.push_back(follow(start));
    types.push_back(start.type);
  }
  if (curves.empty())
    throw NumericalFailure("boundary: no " + (run.type ? to_string(*run.type) : std::string("bifurcation")) +
                           " of the orbit for " + run.y_key + " in [" + format_number(o.y_from) + ", " +
                           format_number(o.y_to) + "] at " + run.x_key + " = " + format_number(o.x_from) +
                           (count > 1 ? " .. " + format_number(o.x_to) : std::string()) + " (N = " +
                           std::to_string(run.Ns.back()) + "; found: " + (found.empty() ? "none" : found) + ")");
  return stable_below;
}

// The levels every point reports, in the JSON's by_N and the CSV's columns: boundary_Ns, then the
// refinement's 2 N and 4 N (null / nan where a point did not need them), so that every point has them all.
std::vector<int> reported_levels(const BoundaryRun& run) {
  std::vector<int> levels = run.Ns;
  levels.insert(levels.end(), run.finer_Ns.begin(), run.finer_Ns.end());
  return levels;
}

// The point of level N's curve in a study: (x, y), NaN where it was not studied or not found.
std::pair<double, double> study_at_level(const BoundaryPointStudy& study, int N) {
  const auto at = std::find(study.levels.begin(), study.levels.end(), N);
  if (at == study.levels.end()) return {NAN, NAN};
  const size_t l = static_cast<size_t>(at - study.levels.begin());
  return {study.x_by_N[l], study.y_by_N[l]};
}

// Each point's study (boundary_point_study) against the curves of the coarser N.
std::vector<BoundaryPointStudy> study_points(const BoundaryRun& run, BifurcationType type,
                                             const BoundaryCurve& curve, Progress& progress, long& evaluations) {
  RichardsonOptions richardson;
  if (run.problem.analyses->switches_in_state() && run.problem.events == EventMode::off)
    richardson.order = richardson.order_step = 1;  // design.md 1.5
  // Blocks of kBlock consecutive points on `threads` threads. Within a block each search starts
  // from the point before's offset; a block's first point from none, whatever the thread count,
  // so the results do not depend on it. Each block has test functions of its own (they keep the
  // last orbit found).
  constexpr size_t kBlock = 16;
  const size_t n = curve.points.size();
  std::vector<BoundaryPointStudy> out(n);
  std::atomic<long> counted_evaluations{0};
  parallel_points(static_cast<long>((n + kBlock - 1) / kBlock), run.threads, [&](long block) {
    std::vector<TestFunctionAt> at_N;
    for (size_t i = 0; i + 1 < run.Ns.size(); ++i) at_N.emplace_back(run, type, run.Ns[i]);
    for (int N : run.finer_Ns) at_N.emplace_back(run, type, N);  // (the last ones)
    long block_evaluations = 0;
    std::vector<BoundaryFunction> counted;
    for (const TestFunctionAt& g : at_N)
      counted.push_back([&g, &block_evaluations](double x, double y) {
        ++block_evaluations;
        return g(x, y);
      });
    const std::vector<BoundaryFunction> coarser(counted.begin(), counted.begin() + (run.Ns.size() - 1));
    const std::vector<BoundaryFunction> finer(counted.end() - static_cast<long>(run.finer_Ns.size()), counted.end());
    const size_t first = static_cast<size_t>(block) * kBlock, end = std::min(n, first + kBlock);
    for (size_t k = first; k < end; ++k) {
      out[k] = boundary_point_study(curve, k, coarser, run.Ns, run.options, richardson, k > first ? &out[k - 1] : nullptr,
                                    finer, run.finer_Ns);
      progress.add();
    }
    counted_evaluations += block_evaluations;
  });
  evaluations += counted_evaluations;
  return out;
}

// The curves found, each with its type and its points' studies.
struct Outcome {
  std::vector<BoundaryCurve> curves;
  std::vector<BifurcationType> types;
  std::vector<std::vector<BoundaryPointStudy>> studies;
  bool stable_below = false;  // stable at y_from wherever the starts were searched
  long evaluations = 0;
  // Wall time of each phase: the starts' search (continue in y), the tracing, the error bars
  double search_seconds = 0, trace_seconds = 0, study_seconds = 0;
  long study_evaluations = 0;  // of the test function at the other levels (the error bars)
  std::string failures;  // the curves that ended in a failure, named
};

Outcome compute_boundary(const BoundaryRun& run, const Invocation& inv) {
  Outcome out;
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  const Clock::time_point search_start = Clock::now();
  out.stable_below = follow_starts(run, out.curves, out.types, [&](const Start& start) {
    const Clock::time_point trace_start = Clock::now();
    const TestFunctionAt finest(run, start.type, run.Ns.back());
    // At the curve's points g itself, but for a grazing curve (the multipliers there too)
    const BoundaryFunction at_points = [&finest](double x, double y) { return finest.at_point(x, y); };
    const bool grazing = start.type == BifurcationType::grazing;
    BoundaryCurve curve =
        trace_boundary_both_ways(std::cref(finest), run.options, start.x, start.y, grazing ? &at_points : nullptr);
    out.trace_seconds += since(trace_start);
    return curve;
  });
  out.search_seconds = since(search_start) - out.trace_seconds;
  const Clock::time_point study_start = Clock::now();
  long points = 0;
  for (const BoundaryCurve& c : out.curves) points += static_cast<long>(c.points.size());
  Progress progress(inv.err, "boundary", points, inv.quiet);
  for (size_t i = 0; i < out.curves.size(); ++i) {
    out.studies.push_back(study_points(run, out.types[i], out.curves[i], progress, out.study_evaluations));
    out.evaluations += out.curves[i].evaluations;
    if (out.curves[i].end == BoundaryEnd::failure)
      out.failures += (out.failures.empty() ? "" : "; ") + std::string("curve ") + std::to_string(i + 1) + " " +
                      out.curves[i].note;
  }
  progress.finish();
  out.study_seconds = since(study_start);
  return out;
}

json boundary_json(const BoundaryRun& run, const Outcome& out, double seconds) {
  json j;
  j["model"] = run.problem.model_name;
  j["boundary_x"] = run.x_key;
  j["boundary_y"] = run.y_key;
  j["N"] = run.Ns.back();
  j["Ns"] = run.Ns;
  j["x_range"] = {run.options.x_from, run.options.x_to};
  j["y_range"] = {run.options.y_from, run.options.y_to};
  j["curves"] = json::array();
  for (size_t i = 0; i < out.curves.size(); ++i) {
    const BoundaryCurve& curve = out.curves[i];
    const std::vector<BoundaryPointStudy>& studies = out.studies[i];
    json c;
    c["type"] = to_string(out.types[i]);
    c["end"] = to_string(curve.end);
    c["note"] = curve.note;
    c["points"] = json::array();
    for (size_t k = 0; k < curve.points.size(); ++k) {
      const BoundaryPoint& p = curve.points[k];
      const BoundaryPointStudy& st = studies[k];
      json by_N = json::array();
      for (int N : reported_levels(run)) {
        const auto [x, y] = study_at_level(st, N);
        by_N.push_back({{"N", N}, {"x", number_or_null(x)}, {"y", number_or_null(y)}});
      }
      c["points"].push_back({{"x", p.x},
                             {"y", p.y},
                             {"angle", number_or_null(p.angle)},
                             {"by_N", by_N},
                             {"extrapolated_from", st.extrapolated_from.empty() ? json(nullptr) : json(st.extrapolated_from)},
                             {"x_extrapolated", number_or_null(st.x_extrapolated)},
                             {"y_extrapolated", number_or_null(st.y_extrapolated)},
                             {"x_error_estimate", number_or_null(st.x_error_estimate)},
                             {"error_estimate", number_or_null(st.y_error_estimate)}});
    }
    c["codim2"] = json::array();
    for (const Codim2Point& q : curve.codim2)
      c["codim2"].push_back({{"kind", q.kind}, {"x", q.x}, {"y", q.y}, {"angle", q.angle}});
    j["curves"].push_back(c);
  }
  // Where the orbit is stable, when the search found it stable at y_from everywhere: below the
  // curves (the side of y_from). A grazing curve bounds the orbits in contact, not a stable region.
  const bool stability_curves = run.type != BifurcationType::grazing;
  j["stable_side"] = out.stable_below && stability_curves ? json("y_from") : json(nullptr);
  if (!out.failures.empty()) j["failure"] = out.failures;
  j["evaluations"] = out.evaluations;
  j["study_evaluations"] = out.study_evaluations;
  j["seconds"] = seconds;
  j["phase_seconds"] = {{"search", out.search_seconds}, {"trace", out.trace_seconds}, {"study", out.study_seconds}};
  return j;
}

// One row per point: its curve's index (from 1), then the point.
std::string boundary_csv(const std::string& header, const BoundaryRun& run, const Outcome& out) {
  std::string text = header + "curve,x,y,angle,y_extrapolated,error_estimate,x_extrapolated,x_error_estimate";
  const std::vector<int> columns = reported_levels(run);
  for (int N : columns) text += ",x_N" + std::to_string(N) + ",y_N" + std::to_string(N);
  text += "\n";
  const auto cell = csv_number;  // (the shortest exact spelling, nan where there is none)
  for (size_t i = 0; i < out.curves.size(); ++i)
    for (size_t k = 0; k < out.curves[i].points.size(); ++k) {
      const BoundaryPoint& p = out.curves[i].points[k];
      const BoundaryPointStudy& study = out.studies[i][k];
      text += std::to_string(i + 1) + "," + cell(p.x) + "," + cell(p.y) + "," + cell(p.angle) + "," +
              cell(study.y_extrapolated) + "," + cell(study.y_error_estimate) + "," + cell(study.x_extrapolated) +
              "," + cell(study.x_error_estimate);
      for (int N : columns) {
        const auto [x, y] = study_at_level(study, N);
        text.append(",").append(cell(x)).append(",").append(cell(y));  // (append: GCC 12's false -Wrestrict)
      }
      text += "\n";
    }
  return text;
}

void print_boundary(std::ostream& os, const BoundaryRun& run, const Outcome& out, double seconds) {
  char line[256];
  os << "delayspec boundary: model " << run.problem.model_name << ", " << out.curves.size() << " curve"
     << (out.curves.size() == 1 ? "" : "s") << " in (" << run.x_key << ", " << run.y_key << "), N = ";
  for (size_t i = 0; i < run.Ns.size(); ++i) os << (i ? "," : "") << run.Ns[i];
  os << "\n";
  for (size_t i = 0; i < out.curves.size(); ++i) {
    const BoundaryCurve& curve = out.curves[i];
    os << "curve " << i + 1 << ": " << to_string(out.types[i]) << ", " << curve.points.size() << " points, ended at `"
       << to_string(curve.end) << "`" << (curve.note.empty() ? "" : ": " + curve.note) << "\n";
    // The extrapolated point lies on the curve's normal through the point at the finest N, so
    // both of its coordinates move, on a lobe's steep side mostly x. On milling_lobes_curves.toml
    // (N = 100, 200, 400) by up to 3.4 rpm: the extrapolated depth read beside the finest N's
    // speed (the table before 2026-11-28) missed by 139 times its +- at the median point, and by
    // 1.3e-3 m on a flip lobe's side.
    std::snprintf(line, sizeof line, "  %-34s  %s\n", ("at N = " + std::to_string(run.Ns.back())).c_str(),
                  "extrapolated (N -> infinity)");
    os << line;
    std::snprintf(line, sizeof line, "  %16s  %16s  %18s  %8s  %18s  %8s  %8s\n", run.x_key.c_str(),
                  run.y_key.c_str(), run.x_key.c_str(), "+-", run.y_key.c_str(), "+-", "angle/pi");
    os << line;
    for (size_t k = 0; k < curve.points.size(); ++k) {
      const BoundaryPoint& p = curve.points[k];
      const BoundaryPointStudy& st = out.studies[i][k];
      std::snprintf(line, sizeof line, "  %16.10g  %16.10g  %18.12g  %8.2g  %18.12g  %8.2g  %8.4f\n", p.x, p.y,
                    st.x_extrapolated, st.x_error_estimate, st.y_extrapolated, st.y_error_estimate,
                    p.angle / std::numbers::pi);
      os << line;
    }
    // (located on the finest N's curve only: the coarser levels' curves are not followed, so
    // nothing says how far it is from N -> infinity)
    for (const Codim2Point& q : curve.codim2)
      os << "  codim 2: " << q.kind << " at " << run.x_key << " = " << format_number(q.x) << ", " << run.y_key
         << " = " << format_number(q.y) << " (at N = " << run.Ns.back() << ", no error estimate)\n";
  }
  os << "time: " << seconds << " s: the starts' search " << format_number(out.search_seconds, 2) << " s, tracing "
     << format_number(out.trace_seconds, 2) << " s (" << out.evaluations << " evaluations of the test function at N = "
     << run.Ns.back() << "), error bars " << format_number(out.study_seconds, 2) << " s (" << out.study_evaluations
     << " at the other N)\n";
}

}  // namespace

int command_boundary(Config& config, const Invocation& inv) {
  // boundary_object = equilibrium: Hopf curves of an equilibrium (boundary_equilibria.hpp)
  if (config.get_choice("boundary_object", "orbit", {"orbit", "equilibrium"}) == "equilibrium")
    return boundary_equilibria(config, inv);
  const auto start_time = std::chrono::steady_clock::now();
  const BoundaryRun run = read_boundary_run(config);
  if (const std::string note = autonomous_fixed_point_note(run.problem); !note.empty() && !inv.quiet)
    inv.err << "delayspec boundary: note: " << note << "\n";
  const Outcome out = compute_boundary(run, inv);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  const json j = boundary_json(run, out, seconds);
  if (inv.out_dir) {
    const std::filesystem::path dir(*inv.out_dir);
    OutputMetadata metadata = make_metadata("boundary", inv.scene, config, j, seconds);
    metadata.parameters.erase(run.x_key);
    metadata.parameters.erase(run.y_key);
    std::string header = metadata_comment_lines(metadata);
    if (!out.failures.empty()) header += "# INCOMPLETE: a curve ended in a failure: " + out.failures + "\n";
    write_output(inv, dir / "boundary.csv", boundary_csv(header, run, out));
    json file = j;
    file["metadata"] = metadata_json(metadata);
    write_output(inv, dir / "boundary.json", file.dump(2) + "\n");
  }
  if (!out.failures.empty()) {
    inv.err << "delayspec boundary: numerical failure: " << out.failures
            << (inv.out_dir ? "; the curves so far are in " + *inv.out_dir : std::string()) << "\n";
    return 3;
  }
  if (inv.json) {
    inv.out << j.dump(2) << "\n";
    return 0;
  }
  print_boundary(inv.out, run, out, seconds);
  return 0;
}

}  // namespace delayspec::cli
