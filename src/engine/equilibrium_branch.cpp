// The branch of equilibria and its fold and Hopf points (equilibrium_branch.hpp for the method).
#include "delayspec/equilibrium_branch.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Dense>

#include "delayspec/detail/illinois.hpp"
#include "delayspec/errors.hpp"

namespace delayspec {

std::string to_string(EquilibriumBifurcationType type) {
  switch (type) {
    case EquilibriumBifurcationType::fold: return "fold";
    case EquilibriumBifurcationType::hopf: return "hopf";
    case EquilibriumBifurcationType::branch_point: return "branch_point";
  }
  return "?";
}

namespace {

// x = (y, p) on the branch, with the unit tangent there.
struct OnBranch {
  Eigen::VectorXd x, tangent;
  double p() const { return x(x.size() - 1); }
  Eigen::VectorXd y() const { return x.head(x.size() - 1); }
};

class Tracer {
 public:
  Tracer(const EquilibriumFamily& family, const EquilibriumBranchOptions& o) : family_(family), o_(o) {}

  // [F_y F_p] at x, F_p by central differences (header comment).
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& x, Eigen::VectorXd* F = nullptr) const {
    const long d = x.size() - 1;
    const Eigen::VectorXd y = x.head(d);
    const double p = x(d), delta = std::cbrt(std::numeric_limits<double>::epsilon()) * (1 + std::abs(p));
    const ConstantHistory h = family_.at(y, p);
    if (F) *F = h.f;
    Eigen::MatrixXd DF(d, d + 1);
    DF.leftCols(d) = h.jacobian();
    DF.col(d) = (family_.at(y, p + delta).f - family_.at(y, p - delta).f) / (2 * delta);
    return DF;
  }

  // The unit null vector of DF, on the side of `previous`.
  static Eigen::VectorXd tangent(const Eigen::MatrixXd& DF, const Eigen::VectorXd& previous) {
    const long n = DF.cols();
    Eigen::MatrixXd M(n, n);
    M << DF, previous.transpose();
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
    rhs(n - 1) = 1;
    Eigen::VectorXd t = Eigen::FullPivLU<Eigen::MatrixXd>(M).solve(rhs);
    return t / t.norm();
  }

  // Corrects the predictor x_pred = from.x + h from.tangent onto the branch (Newton on
  // [F; t . (x - x_pred)]); false when it does not converge.
  bool correct(const OnBranch& from, double h, OnBranch& out, int& iterations) const {
    const Eigen::VectorXd x_pred = from.x + h * from.tangent;
    Eigen::VectorXd x = x_pred;
    const long n = x.size();
    for (iterations = 1; iterations <= o_.newton_iterations; ++iterations) {
      Eigen::VectorXd F;
      const Eigen::MatrixXd DF = jacobian(x, &F);
      Eigen::MatrixXd M(n, n);
      M << DF, from.tangent.transpose();
      Eigen::VectorXd G(n);
      G << F, from.tangent.dot(x - x_pred);
      const Eigen::FullPivLU<Eigen::MatrixXd> lu(M);
      if (!lu.isInvertible() || !G.allFinite()) return false;
      const Eigen::VectorXd dx = lu.solve(G);
      x -= dx;
      if (!x.allFinite()) return false;
      if (dx.lpNorm<Eigen::Infinity>() <= o_.newton_tolerance * (1 + x.lpNorm<Eigen::Infinity>())) {
        out.x = x;
        out.tangent = tangent(jacobian(x), from.tangent);
        return true;
      }
    }
    return false;
  }

  const EquilibriumFamily& family() const { return family_; }
  const EquilibriumBranchOptions& options() const { return o_; }

 private:
  const EquilibriumFamily& family_;
  const EquilibriumBranchOptions& o_;
};

// Roots are refined with the equilibrium's own tolerance.
EquilibriumOptions root_options(const Tracer& tracer) {
  EquilibriumOptions o;
  o.tolerance = tracer.options().newton_tolerance;
  return o;
}

// A root's weight in the count of roots with Re > 0: a complex root stands for its pair.
int weight(const CharacteristicRoot& root) { return root.value.imag() > root.error_bound ? 2 : 1; }

// Roots with Re > 0 among `roots` (Im >= 0 each with its weight: the conjugates are not counted
// twice).
int right_count(const std::vector<CharacteristicRoot>& roots) {
  int count = 0;
  for (const CharacteristicRoot& r : roots)
    if (r.value.imag() >= 0 && r.value.real() > 0) count += weight(r);
  return count;
}

// Roots of `roots` that are the same as lambda: within the Newton tolerance's reach (the roots
// are refined to |step| <= tolerance (1 + |lambda|), their error far below that).
bool same_root(std::complex<double> a, std::complex<double> b, double tolerance) {
  return std::abs(a - b) <= 1e3 * tolerance * (1 + std::abs(a));
}

struct Crossing {
  std::complex<double> at_a, at_b;  // the root at the segment's start (as a lists it) and at its end
};

// What a segment from a to b shows: the roots that crossed the imaginary axis, or why the segment
// cannot be trusted (`why` set: the caller halves the step).
struct SegmentCrossings {
  std::vector<Crossing> crossings;
  std::string why;
};

// Each root of b (Im >= 0) followed back to a by Newton on c there, checked against a's roots
// (header: one to one, onto a listed root, the crossings accounting for the change in count).
SegmentCrossings crossing_roots(const Tracer& tracer, const OnBranch& a, const EquilibriumResult& ra, double p_b,
                                const EquilibriumResult& rb) {
  const double tol = tracer.options().newton_tolerance;
  const ConstantHistory ha = tracer.family().at(a.y(), a.p());
  const double leftmost_a = ra.roots.empty() ? INFINITY : ra.roots.back().value.real();
  SegmentCrossings out;
  std::vector<int> used(ra.roots.size(), 0);
  int change = 0;  // the change in right_count the crossings account for
  for (const CharacteristicRoot& root : rb.roots) {
    if (root.value.imag() < 0) continue;
    CharacteristicRoot back;
    try {
      back = refined_root(ha, root.value, root_options(tracer));
    } catch (const NumericalFailure&) {
      out.why = "the root " + format_complex(root.value) + " at p = " + format_number(p_b) +
                " could not be followed back to p = " + format_number(a.p());
      return out;
    }
    const auto it = std::find_if(ra.roots.begin(), ra.roots.end(), [&](const CharacteristicRoot& r) {
      return r.value.imag() >= 0 && same_root(r.value, back.value, tol);
    });
    if (it == ra.roots.end()) {
      // Left of every root a lists and on b's side of the axis: no crossing, nothing to match.
      if (back.value.real() < leftmost_a && (back.value.real() > 0) == (root.value.real() > 0)) continue;
      // In the left half-plane at both ends: not a crossing, whichever root Newton reached (two
      // real roots 5e-6 apart near -1, one of a decoupled decay z' = -z, swapped places:
      // measured). Should a root that crossed to the left have been followed onto it, the count
      // check below still fails: the crossings found would not account for the change.
      if (back.value.real() < 0 && root.value.real() < 0) continue;
      out.why = "the root " + format_complex(root.value) + " followed back to p = " + format_number(a.p()) +
                " landed on " + format_complex(back.value) + ", which is not among that point's roots";
      return out;
    }
    const size_t j = static_cast<size_t>(it - ra.roots.begin());
    const bool right_a = it->value.real() > 0, right_b = root.value.real() > 0;
    // Two real roots at b onto one complex root at a, neither crossing: the pair of a and its
    // conjugate, which split into two real roots between the points (or merged, followed the other
    // way): no crossing, and the count check below still holds the segment to account.
    if (used[j] == 1 && it->value.imag() > tol * (1 + std::abs(it->value)) && root.value.imag() == 0 &&
        right_a == right_b) {
      ++used[j];
      continue;
    }
    if (used[j]++) {
      out.why = "two roots followed back to p = " + format_number(a.p()) + " landed on the same root " +
                format_complex(it->value);
      return out;
    }
    if (right_a != right_b) {
      out.crossings.push_back({it->value, root.value});
      change += (right_b ? 1 : -1) * weight(root);
    }
  }
  if (right_count(rb.roots) - right_count(ra.roots) != change)
    out.why = "the count of roots with Re lambda > 0 went from " + std::to_string(right_count(ra.roots)) + " to " +
              std::to_string(right_count(rb.roots)) + " but the roots followed account for a change of " +
              std::to_string(change);
  return out;
}

// A check of the location failed: the segment is to be halved (header).
struct Unverified {
  std::string why;
};

// Locates Re lambda = 0 on the segment from a (arclength 0) to b (arclength h, the corrected
// point there), lambda the root followed from lambda_a to lambda_b: Illinois on the arclength s.
// `s` receives the arclength of the location (the order along the segment). Unverified when a
// check of the header fails, NumericalFailure when the bracket does not close in 100 evaluations.
EquilibriumBifurcation locate(const Tracer& tracer, const OnBranch& a, double h, const OnBranch& b,
                              std::complex<double> lambda_a, std::complex<double> lambda_b, double tolerance,
                              double& s_located) {
  struct End {
    double s, p;
    std::complex<double> lambda;
  };
  End lo{0, a.p(), lambda_a}, hi{h, b.p(), lambda_b};
  const double spread_ab = std::abs(lambda_b - lambda_a), root_tol = tracer.options().newton_tolerance;
  // (the end a is hi: a value of hi's sign replaces it, as before illinois.hpp)
  detail::IllinoisValues illinois{hi.lambda.real(), lo.lambda.real()};
  EquilibriumBifurcation out;
  OnBranch at;
  CharacteristicRoot root;
  bool on_axis = false;
  for (out.evaluations = 1; out.evaluations <= 100; ++out.evaluations) {
    const double s = illinois.root(hi.s, lo.s);
    int its = 0;
    if (!tracer.correct(a, s, at, its))
      throw Unverified{"a point inside the segment at p ~ " + format_number(a.p() + (b.p() - a.p()) * s / h) +
                       " could not be corrected onto the branch"};
    s_located = s;
    const double w = (s - lo.s) / (hi.s - lo.s);
    const std::complex<double> guess = (1 - w) * lo.lambda + w * hi.lambda;
    try {
      root = refined_root(tracer.family().at(at.y(), at.p()), guess, root_options(tracer));
    } catch (const NumericalFailure& e) {
      throw Unverified{std::string("refining the crossing root there: ") + e.what()};
    }
    // the same root followed: it moved from the interpolated guess by at most half the spread
    // between the bracket's ends (the path's bend within the bracket), not onto a neighbour
    const double moved = std::abs(root.value - guess), spread = std::abs(hi.lambda - lo.lambda);
    if (moved > 0.5 * spread + 1e3 * root_tol * (1 + std::abs(guess)))
      throw Unverified{"the root refined at p = " + format_number(at.p()) + " moved by " + format_number(moved, 3) +
                       " from " + format_complex(guess) + " to " + format_complex(root.value) +
                       ", more than half the bracket's spread " + format_number(spread, 3) +
                       ": another root, not the one followed"};
    const double g = root.value.real();
    const End c{s, at.p(), root.value};
    // On the axis to rounding: the slope gives the bound. (Not to the root's error_bound, Newton's
    // last step: the root is far more accurate than that, and the bracket goes on shrinking.)
    const double rounding = 4 * std::numeric_limits<double>::epsilon() * (1 + std::abs(root.value));
    if (std::abs(g) <= rounding) {
      out.parameter_bound = rounding * std::abs(hi.p - lo.p) / std::abs(illinois.a - illinois.b);
      on_axis = true;
      break;
    }
    (illinois.replace(g) < 0 ? hi : lo) = c;
    out.parameter_bound = std::abs(hi.p - lo.p);
    if (out.parameter_bound <= tolerance) break;
  }
  if (out.parameter_bound > tolerance)
    throw NumericalFailure("the crossing near p = " + format_number(at.p()) + " was not located to " +
                           format_number(tolerance) + " in 100 evaluations (bracket " +
                           format_number(out.parameter_bound) + ")");
  // The same root at both ends of the final bracket: their distance shrank with the bracket (a
  // root path's speed along the segment may vary by 100x from its mean, not more, before a
  // smaller step is due), so the root is continuous across the location and on the axis there.
  const double closed = std::abs(hi.lambda - lo.lambda);
  if (!on_axis && closed > 100 * spread_ab * std::abs(hi.s - lo.s) / h + 1e3 * root_tol * (1 + std::abs(root.value)))
    throw Unverified{"the bracket around p = " + format_number(at.p()) + " closed between two different roots, " +
                     format_complex(lo.lambda) + " and " + format_complex(hi.lambda)};
  out.parameter = at.p();
  out.state = at.y();
  out.root = root;
  if (root.value.imag() > root.error_bound) {
    out.type = EquilibriumBifurcationType::hopf;
    out.omega = root.value.imag();
    out.period = 2 * std::numbers::pi / out.omega;
  }
  return out;
}

// The equilibrium at p near `guess` with every root that could cross next: at least `nroots` and
// kRootMargin more than it has with Re >= 0 (asked again with more where the first answer has
// too few; fewer come back only where the discretisation has no more to give).
EquilibriumResult tracked_equilibrium(const EquilibriumFamily& family, const Eigen::VectorXd& guess, double p,
                                      int nroots) {
  for (;;) {
    EquilibriumResult r = family.equilibrium(guess, p, nroots);
    const int needed = r.unstable + r.critical + kRootMargin;
    if (needed <= nroots || static_cast<int>(r.roots.size()) < nroots) return r;
    nroots = needed;
  }
}

}  // namespace

EquilibriumBranch continue_equilibrium(const EquilibriumFamily& family, const Eigen::VectorXd& guess,
                                       const EquilibriumBranchOptions& options) {
  EquilibriumBranchOptions o = options;
  static_cast<BranchRange&>(o) = checked_range(options);
  if (o.nroots < 1)
    throw BadInput("`EquilibriumBranchOptions::nroots = " + std::to_string(o.nroots) + "`: must be >= 1");
  const double direction = o.to > o.from ? 1 : -1;
  const Tracer tracer(family, o);
  // the roots to track at the next point: as many as the last point needed (tracked_equilibrium)
  const auto nroots_after = [&o](const EquilibriumResult& r) {
    return std::max(o.nroots, r.unstable + r.critical + kRootMargin);
  };

  EquilibriumBranch branch;
  EquilibriumPoint first{o.from, tracked_equilibrium(family, guess, o.from, o.nroots), 0};
  const long d = first.equilibrium.state.size();
  OnBranch here;
  here.x.resize(d + 1);
  here.x << first.equilibrium.state, o.from;
  Eigen::VectorXd along_p = Eigen::VectorXd::Zero(d + 1);
  along_p(d) = direction;
  here.tangent = Tracer::tangent(tracer.jacobian(here.x), along_p);
  branch.points.push_back(std::move(first));
  if (o.on_point) o.on_point();

  double h = o.step;
  // A step that cannot be taken: halved, or the branch ends with `why` at step_min.
  const auto halve = [&](const std::string& why) {
    h /= 2;
    if (h >= o.step_min) return false;
    branch.end = BranchEnd::failure;
    branch.failure = "at p = " + format_number(here.p()) + " " + why + ", down to continue_step_min = " +
                     format_number(o.step_min);
    return true;
  };
  while (static_cast<int>(branch.points.size()) < o.max_points) {
    OnBranch next;
    int iterations = 0;
    if (!tracer.correct(here, h, next, iterations)) {
      if (halve("no step could be corrected onto the branch")) return branch;
      continue;
    }
    // Past `to`: land on it (Newton at p = to from the point interpolated there); past `from`
    // (the branch turned back): stop.
    const bool past_to = (next.p() - o.to) * direction > 0, past_from = (next.p() - o.from) * direction < 0;
    const EquilibriumResult& previous = branch.points.back().equilibrium;
    EquilibriumPoint point{next.p(), {}, iterations};
    if (past_to) {
      const double w = (o.to - here.p()) / (next.p() - here.p());
      point.parameter = o.to;
      point.equilibrium = tracked_equilibrium(family, (1 - w) * here.y() + w * next.y(), o.to, nroots_after(previous));
    } else {
      point.equilibrium = tracked_equilibrium(family, next.y(), next.p(), nroots_after(previous));
    }
    // every root that crossed, each located on its own, in order of arclength along the segment
    std::vector<std::pair<double, EquilibriumBifurcation>> found;
    const SegmentCrossings segment = crossing_roots(tracer, here, previous, point.parameter, point.equilibrium);
    const bool can_halve = h / 2 >= o.step_min;
    if (!segment.why.empty()) {
      if (halve(segment.why)) return branch;
      continue;
    }
    if (segment.crossings.size() > 1 && can_halve) {
      h /= 2;  // one crossing per segment, where the step allows
      continue;
    }
    try {
      for (const Crossing& c : segment.crossings) {
        double s = 0;
        EquilibriumBifurcation b = locate(tracer, here, h, next, c.at_a, c.at_b, o.tolerance, s);
        if (b.type != EquilibriumBifurcationType::hopf)
          b.type = here.tangent(d) * next.tangent(d) < 0 ? EquilibriumBifurcationType::fold
                                                         : EquilibriumBifurcationType::branch_point;
        else if (family.jacobian)
          b.normal_form = hopf_normal_form(
              [&family, p = b.parameter](const Eigen::VectorXd& y, const Eigen::VectorXd& delayed) {
                return family.jacobian(y, delayed, p);
              },
              family.at(b.state, b.parameter), b.state, b.root);
        if (!past_to || (b.parameter - o.to) * direction <= 0) found.emplace_back(s, std::move(b));
      }
    } catch (const Unverified& e) {
      if (halve("a crossing could not be verified (" + e.why + ")")) return branch;
      continue;
    } catch (const NumericalFailure& e) {  // the branch so far stands; the failure is named
      branch.end = BranchEnd::failure;
      branch.failure = "locating a crossing after p = " + format_number(here.p()) + ": " + e.what();
      return branch;
    }
    std::sort(found.begin(), found.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    for (auto& [s, b] : found) branch.bifurcations.push_back(std::move(b));
    branch.points.push_back(std::move(point));
    if (o.on_point) o.on_point();
    if (past_to) {
      branch.end = BranchEnd::to;
      return branch;
    }
    if (past_from) {
      branch.end = BranchEnd::from;
      return branch;
    }
    here = next;
    if (iterations <= 3) h = std::min(1.5 * h, o.step_max);
  }
  branch.end = BranchEnd::max_points;
  return branch;
}

}  // namespace delayspec
