#include "delayspec/boundary_diagram.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <utility>

#include "delayspec/continuation.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/parallel_points.hpp"

namespace delayspec {

namespace {

// What every part of the diagram reads: the family, the options, the parameters' names.
struct Diagram {
  std::shared_ptr<const ProblemFamily> family;
  const BoundaryDiagramOptions& o;
  std::string x_name, y_name;

  std::vector<double> values_at(double x, double y) const {
    return ProblemFamily::with(ProblemFamily::with(o.values, o.x, x), o.y, y);
  }
  MapSettings map_at(int N) const {
    MapSettings map = o.map;
    map.N = N;
    return map;
  }
};

// The test function of `type` at (x, y) at one N: the model at both values, its orbit and
// leading multipliers. A nonlinear model's orbit is found by Newton from the last one found.
// at_point: at a point of the traced curve, whose sample also carries where it meets a curve of
// the other kind (boundary.hpp's at_points): on a grazing curve this needs the multipliers too.
class TestFunctionAt {
 public:
  TestFunctionAt(const Diagram& diagram, BifurcationType type, int N)
      : diagram_(diagram), type_(type), map_(diagram.map_at(N)), orbit_settings_(diagram.o.orbit) {
    // From the last point's orbit: one Newton step even when it meets the tolerance (orbit_newton.hpp)
    orbit_settings_.newton.min_iterations = 1;
  }
  BoundarySample operator()(double x, double y) const { return evaluate(x, y, false); }
  BoundarySample at_point(double x, double y) const { return evaluate(x, y, true); }

 private:
  BoundarySample evaluate(double x, double y, bool on_curve) const {
    const FamilyMember member = diagram_.family->at(diagram_.values_at(x, y), map_);
    if (!member) return undefined(member.rejected);  // a value the model refuses
    try {
      if (last_orbit_.size() > 0) {
        try {
          return sample(*member.analyses, &last_orbit_, on_curve);
        } catch (const NumericalFailure&) {  // Newton from the last orbit: the search from scratch below
        }
      }
      return sample(*member.analyses, nullptr, on_curve);
    } catch (const BadInput& e) {  // an analysis that refuses this point
      return undefined(e.what());
    } catch (const NumericalFailure& e) {  // an orbit or an eigensolver that fails
      return undefined(e.what());
    }
  }

  // The test function on the orbit found by Newton from `guess` (the last orbit found), or
  // (nullptr) by the orbit search of the options.
  BoundarySample sample(const ModelAnalyses& analyses, const Eigen::VectorXd* guess, bool on_curve) const {
    OrbitRequest request;
    request.sequence = !analyses.is_linear();
    request.newton_guess = guess;
    request.align_contacts = false;  // as the curve's branches are continued (model_analyses.hpp)
    // A grazing curve: the orbit of the field below the surface (step_options.hpp's
    // fixed_region), smooth where the switched orbit starts to touch; the same orbit where max H <= 0.
    MapSettings map = map_;
    const bool grazing = type_ == BifurcationType::grazing;
    if (grazing) map.step.fixed_region = 2;
    const LinearisedOrbit at = analyses.linearised_orbit(map, orbit_settings_, request);
    // Grazing: max H, and at a point of the curve the multipliers, where the eigensolver converges
    // (a failure there only hides where the curve meets a stability curve).
    FloquetResult r;
    if (!grazing) {
      r = floquet_multipliers(*at.monodromy, diagram_.o.floquet);
    } else if (on_curve) {
      try {
        r = floquet_multipliers(*at.monodromy, diagram_.o.floquet);
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
  const Diagram& diagram_;
  BifurcationType type_;
  MapSettings map_;
  OrbitSettings orbit_settings_;
  mutable Eigen::VectorXd last_orbit_;
};

// A curve's start: a bifurcation the continuation in y located at x (the finest N).
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
Search search_at(const Diagram& d, double x, int N) {
  const BoundaryOptions& c = d.o.curve;
  const std::vector<double> values = d.values_at(x, c.y_from);
  const FamilyMember member = d.family->at(values, d.map_at(N));
  if (!member) throw BadInput(member.rejected);
  ContinuationOptions search;
  search.from = c.y_from;
  search.to = c.y_to;
  search.tolerance = c.tolerance * std::abs(c.y_to - c.y_from);
  search.N = N;
  search.periods_per_map = d.o.map.orbit_period;
  search.step_options = d.o.map.step;
  search.floquet = d.o.floquet;
  search.newton.tolerance = d.o.orbit.newton.tolerance;
  search.start_iterations = d.o.orbit.newton.max_iterations;
  const ContinuationResult branch =
      member.analyses->continue_orbit(analyses_along(d.family, values, d.o.y, d.map_at(N)), d.o.orbit, search);
  Search out;
  out.stable_at_y_from = !branch.points.empty() && branch.points.front().stable();
  out.failure = branch.failure;
  for (const Bifurcation& b : branch.bifurcations) {
    out.found += (out.found.empty() ? "" : ", ") + to_string(b.type) + " at " + format_number(b.parameter);
    if (d.o.type ? *d.o.type == b.type : b.type != BifurcationType::grazing) out.starts.push_back({b.type, x, b.parameter});
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
std::optional<Start> at_finest_N(const Diagram& d, const Start& coarse) {
  const TestFunctionAt g(d, coarse.type, d.o.Ns.back());
  const double range = d.o.curve.y_to - d.o.curve.y_from;
  const double s = boundary_offset_along(std::cref(g), coarse.x, coarse.y, 0, range, 1e-6, d.o.curve.tolerance);
  if (!(std::abs(s) <= 0.1)) return std::nullopt;
  return Start{coarse.type, coarse.x, coarse.y + s * range};
}

// The first start in y at x: searched at the coarsest N of Ns and moved to the finest
// (at_finest_N): on milling_lobes_curves.toml the 40 starts' search took 0.26 s instead of
// 0.36-0.44 at N = 400 (a continuation at N = 100 costs half one at 400: its fixed costs
// dominate). Searched at the finest N where the coarsest finds none or the move fails.
Search first_start_at(const Diagram& d, double x) {
  if (d.o.Ns.size() > 1) {
    try {
      Search coarse = search_at(d, x, d.o.Ns.front());
      if (!coarse.starts.empty())
        if (const std::optional<Start> start = at_finest_N(d, coarse.starts.front())) {
          coarse.starts = {*start};
          return coarse;
        }
    } catch (const NumericalFailure&) {  // (the finest N's search below says what fails)
    }
  }
  return search_at(d, x, d.o.Ns.back());
}

// The starts of the curves: the first bifurcation of the type at x_from (no scan), or (scan) the
// first one in y at each of scan_points values of x, less those on a curve already followed
// (`follow` is called for each start in turn). Returns stable_below: the orbit is stable at
// y_from at every x searched (the side of the curves a chart would call stable).
// NumericalFailure when there is no start at all, with what was found.
template <class Follow>
bool follow_starts(const Diagram& d, std::vector<BoundaryCurve>& curves, std::vector<BifurcationType>& types,
                   Follow follow) {
  const BoundaryOptions& o = d.o.curve;
  const int count = d.o.scan_points > 0 ? d.o.scan_points : 1;
  const auto x_of = [&](long i) { return count == 1 ? o.x_from : o.x_from + (o.x_to - o.x_from) * i / (count - 1); };
  // The searches first, on `threads` threads (none depends on the curves), then the curves
  // followed in the order of x: the same curves for any thread count.
  std::vector<Search> searches(static_cast<size_t>(count));
  std::vector<std::string> failed(static_cast<size_t>(count));  // a search's NumericalFailure
  parallel_points(count, d.o.threads, [&](long i) {
    try {
      searches[static_cast<size_t>(i)] = first_start_at(d, x_of(i));
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
      found += (found.empty() ? "" : "; ") + d.x_name + " = " + format_number(x) + ": " + failed[static_cast<size_t>(i)];
      stable_below = false;
      continue;
    }
    stable_below = stable_below && search.stable_at_y_from;
    if (!search.found.empty())
      found += (found.empty() ? "" : "; ") + d.x_name + " = " + format_number(x) + ": " + search.found;
    if (search.starts.empty()) continue;
    const Start& start = search.starts.front();  // the first in y: where the orbit loses (or gains) stability
    if (on_boundary_curve(curves, start.x, start.y, 1e-3 * std::abs(o.y_to - o.y_from))) continue;
    curves.push_back(follow(start));
    types.push_back(start.type);
  }
  if (curves.empty())
    throw NumericalFailure("boundary: no " + (d.o.type ? to_string(*d.o.type) : std::string("bifurcation")) +
                           " of the orbit for " + d.y_name + " in [" + format_number(o.y_from) + ", " +
                           format_number(o.y_to) + "] at " + d.x_name + " = " + format_number(o.x_from) +
                           (count > 1 ? " .. " + format_number(o.x_to) : std::string()) + " (N = " +
                           std::to_string(d.o.Ns.back()) + "; found: " + (found.empty() ? "none" : found) + ")");
  return stable_below;
}

// Each point's study (boundary_point_study) against the curves of the coarser N.
std::vector<BoundaryPointStudy> study_points(const Diagram& d, BifurcationType type, const BoundaryCurve& curve,
                                             long& evaluations) {
  // Blocks of kBlock consecutive points on `threads` threads. Within a block each search starts
  // from the point before's offset; a block's first point from none, whatever the thread count,
  // so the results do not depend on it. Each block has test functions of its own (they keep the
  // last orbit found).
  constexpr size_t kBlock = 16;
  const std::vector<int>& Ns = d.o.Ns;
  const std::vector<int>& finer_Ns = d.o.finer_Ns;
  const size_t n = curve.points.size();
  std::vector<BoundaryPointStudy> out(n);
  std::atomic<long> counted_evaluations{0};
  parallel_points(static_cast<long>((n + kBlock - 1) / kBlock), d.o.threads, [&](long block) {
    std::vector<TestFunctionAt> at_N;
    for (size_t i = 0; i + 1 < Ns.size(); ++i) at_N.emplace_back(d, type, Ns[i]);
    for (int N : finer_Ns) at_N.emplace_back(d, type, N);  // (the last ones)
    long block_evaluations = 0;
    std::vector<BoundaryFunction> counted;
    for (const TestFunctionAt& g : at_N)
      counted.push_back([&g, &block_evaluations](double x, double y) {
        ++block_evaluations;
        return g(x, y);
      });
    const std::vector<BoundaryFunction> coarser(counted.begin(), counted.begin() + static_cast<long>(Ns.size() - 1));
    const std::vector<BoundaryFunction> finer(counted.end() - static_cast<long>(finer_Ns.size()), counted.end());
    const size_t first = static_cast<size_t>(block) * kBlock, end = std::min(n, first + kBlock);
    for (size_t k = first; k < end; ++k) {
      out[k] = boundary_point_study(curve, k, coarser, Ns, d.o.curve, d.o.richardson, k > first ? &out[k - 1] : nullptr,
                                    finer, finer_Ns);
      if (d.o.on_point_studied) d.o.on_point_studied();
    }
    counted_evaluations += block_evaluations;
  });
  evaluations += counted_evaluations;
  return out;
}

}  // namespace

BoundaryDiagram boundary_diagram(std::shared_ptr<const ProblemFamily> family, const BoundaryDiagramOptions& options) {
  const size_t parameters = family->parameter_names().size();
  for (const int index : {options.x, options.y})
    if (index < 0 || static_cast<size_t>(index) >= parameters)
      throw BadInput("boundary_diagram: parameter index " + std::to_string(index) + " outside the family's " +
                     std::to_string(parameters));
  if (options.x == options.y) throw BadInput("boundary_diagram: x and y are the same parameter");
  if (options.values.size() != parameters)
    throw BadInput("boundary_diagram: " + std::to_string(options.values.size()) + " values for " +
                   std::to_string(parameters) + " parameters");
  if (options.Ns.empty()) throw BadInput("boundary_diagram: no levels N");
  const Diagram d{family, options, family->parameter_names()[static_cast<size_t>(options.x)],
                  family->parameter_names()[static_cast<size_t>(options.y)]};

  BoundaryDiagram out;
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  const Clock::time_point search_start = Clock::now();
  out.stable_below = follow_starts(d, out.curves, out.types, [&](const Start& start) {
    const Clock::time_point trace_start = Clock::now();
    const TestFunctionAt finest(d, start.type, options.Ns.back());
    // At the curve's points g itself, but for a grazing curve (the multipliers there too)
    const BoundaryFunction at_points = [&finest](double x, double y) { return finest.at_point(x, y); };
    const bool grazing = start.type == BifurcationType::grazing;
    BoundaryCurve curve =
        trace_boundary_both_ways(std::cref(finest), options.curve, start.x, start.y, grazing ? &at_points : nullptr);
    out.trace_seconds += since(trace_start);
    return curve;
  });
  out.search_seconds = since(search_start) - out.trace_seconds;
  const Clock::time_point study_start = Clock::now();
  long points = 0;
  for (const BoundaryCurve& c : out.curves) points += static_cast<long>(c.points.size());
  if (options.on_studies) options.on_studies(points);
  for (size_t i = 0; i < out.curves.size(); ++i) {
    out.studies.push_back(study_points(d, out.types[i], out.curves[i], out.study_evaluations));
    out.evaluations += out.curves[i].evaluations;
    if (out.curves[i].end == BoundaryEnd::failure)
      out.failures += (out.failures.empty() ? "" : "; ") + std::string("curve ") + std::to_string(i + 1) + " " +
                      out.curves[i].note;
  }
  out.study_seconds = since(study_start);
  return out;
}

}  // namespace delayspec
