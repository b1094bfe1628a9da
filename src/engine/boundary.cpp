#include "delayspec/boundary.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>

#include "delayspec/detail/bifurcation_locator.hpp"  // multiplier_test
#include "delayspec/detail/illinois.hpp"
#include "delayspec/errors.hpp"

namespace delayspec {

std::string to_string(BoundaryEnd end) {
  switch (end) {
    case BoundaryEnd::to: return "to";
    case BoundaryEnd::from: return "from";
    case BoundaryEnd::y_range: return "y_range";
    case BoundaryEnd::codim2: return "codim2";
    case BoundaryEnd::max_points: return "max_points";
    case BoundaryEnd::failure: return "failure";
  }
  return "?";
}

std::string to_string(const Codim2Point& point) {
  switch (point.kind) {
    case Codim2Kind::resonance_1_1: return "1:1 resonance";
    case Codim2Kind::resonance_1_2: return "1:2 resonance";
    case Codim2Kind::grazing_meets: return "grazing meets " + to_string(point.met);
  }
  return "?";
}

BoundarySample boundary_sample(BifurcationType type, const std::vector<std::complex<double>>& multipliers,
                               double max_H) {
  BoundarySample s;
  if (type == BifurcationType::grazing) {
    s.value = max_H;
    s.defined = std::isfinite(max_H);
    if (!s.defined) s.reason = "no max H (the model does not switch in the state)";
    if (!multipliers.empty()) {
      const std::complex<double> mu1 = *std::max_element(
          multipliers.begin(), multipliers.end(), [](auto a, auto b) { return std::abs(a) < std::abs(b); });
      s.other = std::abs(mu1) - 1;
      s.other_type = crossing_type(mu1);
      s.other_angle = std::abs(std::arg(mu1));
    }
    return s;
  }
  std::complex<double> critical;
  s.value = continuation_detail::multiplier_test(type, multipliers, &critical);
  s.defined = std::isfinite(s.value);
  if (s.defined) s.angle = std::abs(std::arg(critical));
  else s.reason = "no " + to_string(type) + " candidate among the " + std::to_string(multipliers.size()) +
                  " leading multipliers";
  if (s.defined && type != BifurcationType::neimark_sacker) {
    const double target = type == BifurcationType::fold ? 1.0 : -1.0;
    bool skipped = false;  // the critical multiplier itself, once
    for (const std::complex<double>& mu : multipliers) {
      if (!skipped && mu == critical) {
        skipped = true;
        continue;
      }
      const double gap = std::abs(mu - target);
      if (!(gap >= s.second_gap)) {  // (NaN at first)
        s.second_gap = gap;
        s.second_side = std::abs(mu) - 1;
      }
    }
  }
  s.other = std::isfinite(max_H) ? max_H : NAN;
  s.other_type = type;
  s.other_angle = s.angle;
  return s;
}

namespace {

using Vec2 = std::array<double, 2>;

double dot(const Vec2& a, const Vec2& b) { return a[0] * b[0] + a[1] * b[1]; }
double norm(const Vec2& a) { return std::sqrt(dot(a, a)); }

// The curve in the scaled plane: g at a scaled point, counted.
class ScaledCurve {
 public:
  ScaledCurve(const BoundaryFunction& g, const BoundaryFunction* at_points, const BoundaryOptions& o,
              long& evaluations)
      : g_(g), at_points_(at_points ? *at_points : g), o_(o), evaluations_(evaluations) {}
  double x(const Vec2& X) const { return o_.x_from + X[0] * (o_.x_to - o_.x_from); }
  double y(const Vec2& X) const { return o_.y_from + X[1] * (o_.y_to - o_.y_from); }
  BoundarySample at(const Vec2& X) const { return evaluate(g_, X); }
  // At a point of the curve (trace_boundary's at_points).
  BoundarySample at_point(const Vec2& X) const { return evaluate(at_points_, X); }
  // Whether the curve's points need at_point: without it, g's last value at a corrector iterate
  // serves (the point moves by <= the tolerance after it).
  bool separate_at_points() const { return &at_points_ != &g_; }
  // grad g at X (g(X) = g0 known) by forward differences; nullopt where g is undefined.
  std::optional<Vec2> gradient(const Vec2& X, double g0, std::string& reason) const {
    constexpr double kDelta = 1e-7;
    Vec2 grad{};
    for (int k = 0; k < 2; ++k) {
      Vec2 Y = X;
      Y[k] += kDelta;
      const BoundarySample s = at(Y);
      if (!s.defined) {
        reason = s.reason;
        return std::nullopt;
      }
      grad[k] = (s.value - g0) / kDelta;
    }
    if (!(norm(grad) > 0) || !std::isfinite(norm(grad))) {
      reason = "the test function's gradient is zero or not finite";
      return std::nullopt;
    }
    return grad;
  }

 private:
  BoundarySample evaluate(const BoundaryFunction& f, const Vec2& X) const {
    ++evaluations_;
    try {
      return f(x(X), y(X));
    } catch (const NumericalFailure& e) {
      BoundarySample s;
      s.reason = e.what();
      return s;
    }
  }
  const BoundaryFunction& g_;
  const BoundaryFunction& at_points_;
  const BoundaryOptions& o_;
  long& evaluations_;
};

// A point on the curve with what the next step needs.
struct CurveState {
  Vec2 X;
  BoundarySample sample;
  Vec2 grad;  // grad g there: at the start by differences, then the corrector's (below)
  Vec2 t;     // unit tangent along the curve
  int iterations = 0;
  std::optional<Vec2> before;  // the point before (the tangent's quadratic), none at a start
};

// The unit tangent for the gradient `grad`, oriented along `along`.
Vec2 tangent_of(const Vec2& grad, const Vec2& along) {
  Vec2 t{-grad[1], grad[0]};
  const double n = norm(t);
  t = {t[0] / n, t[1] / n};
  if (dot(t, along) < 0) t = {-t[0], -t[1]};
  return t;
}

// Chord Newton from X0 on g = 0 and c(X) = <row, X> - rhs = 0 (the arclength condition, or u or
// v fixed), with the gradient `grad` of the last accepted point. nullopt and the reason on failure.
std::optional<CurveState> correct(const ScaledCurve& curve, Vec2 X, const Vec2& grad, const Vec2& row, double rhs,
                                  double tolerance, std::string& reason) {
  const double det = grad[0] * row[1] - grad[1] * row[0];
  if (!(std::abs(det) > 1e-14 * norm(grad) * norm(row))) {
    reason = "the corrector's matrix is singular";
    return std::nullopt;
  }
  // The g row is updated by Broyden's rule after each step (G += (dg - G dX) dX^T / |dX|^2: the
  // secant condition along the step taken; the arclength row is exact), which makes the chord's
  // linear convergence superlinear at no extra evaluation.
  Vec2 G = grad;
  double D = det, last_g = 0;
  Vec2 last_dX{0, 0};
  for (int it = 1; it <= 8; ++it) {
    const BoundarySample s = curve.at(X);
    if (!s.defined) {
      reason = s.reason;
      return std::nullopt;
    }
    const double r0 = s.value, r1 = dot(row, X) - rhs;
    const double dd = dot(last_dX, last_dX);  // (0 before the first step)
    if (dd > 0) {
      const double miss = (r0 - last_g) - dot(G, last_dX);
      const Vec2 updated{G[0] + miss * last_dX[0] / dd, G[1] + miss * last_dX[1] / dd};
      const double updated_det = updated[0] * row[1] - updated[1] * row[0];
      if (std::abs(updated_det) > 1e-14 * norm(updated) * norm(row)) G = updated, D = updated_det;
    }
    // [G; row] dX = -(r0, r1)
    const Vec2 dX{-(r0 * row[1] - r1 * G[1]) / D, -(G[0] * r1 - row[0] * r0) / D};
    last_g = r0;
    last_dX = dX;
    X = {X[0] + dX[0], X[1] + dX[1]};
    if (norm(dX) <= tolerance) {
      CurveState state;
      state.X = X;
      // The sample of the last iterate, a step <= tolerance away, unless the points need their own
      state.sample = curve.separate_at_points() ? curve.at_point(X) : s;
      if (!state.sample.defined) {
        reason = state.sample.reason;
        return std::nullopt;
      }
      state.grad = G;
      state.iterations = it;
      return state;
    }
    if (!std::isfinite(X[0]) || !std::isfinite(X[1])) break;
  }
  reason = "the corrector did not converge in 8 iterations";
  return std::nullopt;
}

// A codim-2 point passed between the last three points a, b, c (scaled positions, arclengths
// s, angles): the critical pair's angle runs through pi (or 0) as the multipliers pass -1 (or +1)
// along the circle, so |arg mu| folds there: a V with its vertex between a and c, the angle's
// largest (smallest) value at b. The vertex from the two straight sides: on the side of b away
// from the vertex the slope is that of the pair's motion; the side whose prediction of the third
// point fits better. Nothing when the angle does not turn at b within 0.1 of pi or 0.
std::optional<Codim2Point> passed_resonance(const std::array<Vec2, 3>& X, const std::array<double, 3>& s,
                                            const std::array<double, 3>& angle) {
  for (double a : angle)
    if (!std::isfinite(a)) return std::nullopt;
  const double d1 = angle[1] - angle[0], d2 = angle[2] - angle[1];
  if (!(d1 * d2 < 0)) return std::nullopt;
  const bool at_pi = d1 > 0;  // a maximum: the angle folds at pi; a minimum: at 0
  const double edge = at_pi ? std::numbers::pi : 0.0;
  if (std::abs(angle[1] - edge) > 0.1) return std::nullopt;
  const double left = std::abs(d1) / (s[1] - s[0]), right = std::abs(d2) / (s[2] - s[1]);
  const double gap = std::abs(edge - angle[1]);
  // Vertex right of b (the left side's slope continues to it), or left of b.
  const double s_right = s[1] + gap / left, s_left = s[1] - gap / right;
  const double miss_right = std::abs(std::abs(edge - angle[2]) - left * std::abs(s[2] - s_right));
  const double miss_left = std::abs(std::abs(edge - angle[0]) - right * std::abs(s_left - s[0]));
  double vertex = miss_right < miss_left ? s_right : s_left;
  vertex = std::clamp(vertex, s[0], s[2]);
  const int k = vertex <= s[1] ? 0 : 1;  // the segment holding it
  const double w = (vertex - s[k]) / (s[k + 1] - s[k]);
  Codim2Point q;
  q.kind = at_pi ? Codim2Kind::resonance_1_2 : Codim2Kind::resonance_1_1;
  q.x = X[k][0] + w * (X[k + 1][0] - X[k][0]);  // (scaled; the caller maps to x, y)
  q.y = X[k][1] + w * (X[k + 1][1] - X[k][1]);
  q.angle = edge;
  return q;
}

// The start: on the line u = 0 (y located by the caller, corrected here with x fixed), with its
// gradient and its tangent toward x_to. NumericalFailure when g is undefined there or the
// corrector moves y by more than 1e-6 of the range (the caller's point is not on the curve).
CurveState start_of_curve(const ScaledCurve& scaled, double y_start, const BoundaryOptions& o) {
  std::string reason;
  const Vec2 X0{0, (y_start - o.y_from) / (o.y_to - o.y_from)};
  const BoundarySample s0 = scaled.at(X0);
  if (!s0.defined) throw NumericalFailure("boundary: the test function is not defined at the start: " + s0.reason);
  const std::optional<Vec2> grad0 = scaled.gradient(X0, s0.value, reason);
  if (!grad0) throw NumericalFailure("boundary: at the start: " + reason);
  std::optional<CurveState> start = correct(scaled, X0, *grad0, {1, 0}, 0, o.tolerance, reason);
  if (!start || std::abs(start->X[1] - X0[1]) > 1e-6)
    throw NumericalFailure("boundary: the start (x = " + format_number(o.x_from) + ", y = " + format_number(y_start) +
                           ") is not on the curve" + (start ? "" : ": " + reason));
  start->grad = *grad0;
  start->t = tangent_of(start->grad, {1, 0});
  return *start;
}

// The predictor from `at` by ds along its tangent, with the corrector's second equation: the
// arclength condition, or, where the step would pass u = 1 (x_to), u = 0 (back at x_from) or the
// y range's edge, the step shortened to land there and that coordinate fixed (`landing` names it).
struct Predictor {
  Vec2 P, row;
  double rhs = 0, ds = 0;
  BoundaryEnd landing = BoundaryEnd::max_points;  // (max_points: none)
};
Predictor predict(const CurveState& at, double ds) {
  const auto along = [&](double step) { return Vec2{at.X[0] + step * at.t[0], at.X[1] + step * at.t[1]}; };
  Predictor p{along(ds), at.t, 0, ds, BoundaryEnd::max_points};
  p.rhs = dot(at.t, p.P);
  const auto land = [&](int k, double edge, BoundaryEnd end) {
    const double s = (edge - at.X[k]) / at.t[k];
    if (!(s > 0 && s <= p.ds)) return;
    p.ds = s;
    p.P = along(s);
    p.P[k] = edge;
    p.row = k == 0 ? Vec2{1, 0} : Vec2{0, 1};
    p.rhs = edge;
    p.landing = end;
  };
  if (p.P[0] > 1) land(0, 1, BoundaryEnd::to);
  else if (p.P[0] < 0) land(0, 0, BoundaryEnd::from);
  if (p.P[1] > 1) land(1, 1, BoundaryEnd::y_range);
  else if (p.P[1] < 0) land(1, 0, BoundaryEnd::y_range);
  return p;
}

// The unit tangent at c from the curve's last points a (optional), b, c: the derivative at c of
// the quadratic through them in chord length (h1 = |b - a|, h2 = |c - b|, d1 and d2 the chords'
// unit directions),
//
//   X'(c) = d2 + h2 (d2 - d1) / (h1 + h2),
//
// second-order in the steps; without a, the chord's reflection of b's tangent t_b (exact on a
// circle: the chord halves the angle between the tangents at its ends).
Vec2 tangent_through(const std::optional<Vec2>& a, const Vec2& b, const Vec2& c, const Vec2& t_b) {
  const Vec2 chord{c[0] - b[0], c[1] - b[1]};
  const double h2 = norm(chord);
  const Vec2 d2{chord[0] / h2, chord[1] / h2};
  Vec2 t;
  if (a) {
    const Vec2 back{b[0] - (*a)[0], b[1] - (*a)[1]};
    const double h1 = norm(back);
    const Vec2 d1{back[0] / h1, back[1] / h1};
    t = {d2[0] + h2 * (d2[0] - d1[0]) / (h1 + h2), d2[1] + h2 * (d2[1] - d1[1]) / (h1 + h2)};
  } else {
    const double c2 = 2 * dot(d2, t_b);
    t = {c2 * d2[0] - t_b[0], c2 * d2[1] - t_b[1]};
  }
  const double n = norm(t);
  return {t[0] / n, t[1] / n};
}

// The corrected point of the predictor with its gradient and tangent; nullopt and the reason when
// the corrector fails, g is undefined, or the tangent turns by more than ~37 degrees. No
// evaluation beyond the corrector's: the tangent from the curve's last points (tangent_through),
// the gradient the corrector's Broyden row turned normal to it (on the curve grad g is normal to
// it; the row's component there is the normal derivative the corrector's steps measured). On
// milling_lobes_curves.toml 5.9 evaluations a point instead of 7.9 with a gradient by
// differences and g again at the converged point (then with steps set by the iterations).
std::optional<CurveState> next_point(const ScaledCurve& scaled, const CurveState& current, const Predictor& p,
                                     double tolerance, std::string& reason) {
  std::optional<CurveState> next = correct(scaled, p.P, current.grad, p.row, p.rhs, tolerance, reason);
  if (!next) return std::nullopt;
  // The corrector moves the predictor by about the curve's bend, kappa ds^2 / 2: a move longer
  // than the step itself went to another part of the zero set (seen: from a lobe's start to a
  // point 4 y ranges away, at 15 starts on milling_lobes_curves.toml). So does a point outside
  // the scaled box, where the predictor's landing did not see the curve leave it.
  const double moved = norm({next->X[0] - p.P[0], next->X[1] - p.P[1]});
  const double margin = 1e-9;
  if (moved > p.ds || next->X[0] < -margin || next->X[0] > 1 + margin || next->X[1] < -margin ||
      next->X[1] > 1 + margin) {
    reason = "the corrector left the step's neighbourhood or the ranges";
    return std::nullopt;
  }
  next->t = tangent_through(current.before, current.X, next->X, current.t);
  if (dot(next->t, current.t) < 0) next->t = {-next->t[0], -next->t[1]};
  if (dot(next->t, current.t) < 0.8) {
    reason = "the tangent turned by more than 37 degrees";
    return std::nullopt;
  }
  const Vec2 normal{next->t[1], -next->t[0]};
  const double along = dot(next->grad, normal);
  if (!(std::abs(along) > 0) || !std::isfinite(along)) {
    reason = "the test function's normal derivative is zero or not finite";
    return std::nullopt;
  }
  next->grad = {along * normal[0], along * normal[1]};
  next->before = current.X;
  return next;
}

// The end of a curve that cannot go on from `last` (step below step_min): a codim-2 point where a
// critical pair met the real axis (the last angle within 0.05 of 0 or pi), else a failure. On a
// fold or period-doubling curve the angle is 0 or pi throughout: there the resonance also needs a
// second multiplier within 0.05 of the critical point (two real multipliers meeting at +1 or -1).
void end_where_it_stops(BoundaryCurve& curve, const ScaledCurve& scaled, const CurveState& last,
                        const std::string& reason) {
  const double angle = last.sample.angle, x = scaled.x(last.X), y = scaled.y(last.X);
  const bool pair = last.sample.other_type == BifurcationType::neimark_sacker;
  if (std::isfinite(angle) && (angle < 0.05 || angle > std::numbers::pi - 0.05) &&
      (pair || last.sample.second_gap < 0.05)) {
    const bool one_to_one = angle < 0.05;
    Codim2Point q;
    q.kind = one_to_one ? Codim2Kind::resonance_1_1 : Codim2Kind::resonance_1_2;
    q.x = x;
    q.y = y;
    q.angle = angle;
    curve.codim2.push_back(q);
    curve.end = BoundaryEnd::codim2;
    curve.note = std::string("the critical pair reached the real axis (angle ") + format_number(angle, 3) + "): " +
                 (one_to_one ? "1:1" : "1:2") + " resonance at x = " + format_number(x) + ", y = " + format_number(y);
  } else {
    curve.end = BoundaryEnd::failure;
    curve.note = "at x = " + format_number(x) + ", y = " + format_number(y) + ": " + reason;
  }
}

// Where `field` of the samples changes sign between the accepted points a and b: regula falsi
// (Illinois) on the position w in [0, 1] along the chord from a to b, each trial point a + w (b -
// a) corrected onto the curve across the chord (the row of the chord's direction), until the
// bracket is shorter than the tolerance. Nothing when the signs do not differ; the point where
// the bracket last stood when a correction fails (it lies between two points of the curve, to the
// chord's bend), with `closed` false.
std::optional<CurveState> sign_change_between(const ScaledCurve& scaled, const CurveState& a, const CurveState& b,
                                              double tolerance, double BoundarySample::*field, bool& closed) {
  const double fa = a.sample.*field, fb = b.sample.*field;
  if (!std::isfinite(fa) || !std::isfinite(fb) || (fa > 0) == (fb > 0)) return std::nullopt;
  const Vec2 chord{b.X[0] - a.X[0], b.X[1] - a.X[1]};
  const double length = norm(chord);
  const Vec2 row{chord[0] / length, chord[1] / length};
  double wa = 0, wb = 1;
  CurveState at = std::abs(fa) < std::abs(fb) ? a : b;
  detail::IllinoisValues illinois{fa, fb};
  closed = false;
  for (int it = 0; it < 40 && !(closed = (wb - wa) * length <= tolerance); ++it) {
    const double w = std::clamp(illinois.root(wa, wb), wa, wb);
    const Vec2 P{a.X[0] + w * chord[0], a.X[1] + w * chord[1]};
    std::string reason;
    const std::optional<CurveState> on = correct(scaled, P, a.grad, row, dot(row, P), tolerance, reason);
    if (!on || !std::isfinite(on->sample.*field)) break;
    at = *on;
    const double f = on->sample.*field;
    if (f == 0) {
      closed = true;
      break;
    }
    (illinois.replace(f) < 0 ? wa : wb) = w;
  }
  return at;
}

// Where a grazing curve meets a stability curve between a and b: the sign change of the other
// kind's test function (BoundarySample::other).
std::optional<Codim2Point> met_other_curve(const ScaledCurve& scaled, const CurveState& a, const CurveState& b,
                                           double tolerance) {
  bool closed = false;  // (where it stands otherwise: the meeting lies between a and b)
  const std::optional<CurveState> at = sign_change_between(scaled, a, b, tolerance, &BoundarySample::other, closed);
  if (!at) return std::nullopt;
  Codim2Point q;
  q.kind = Codim2Kind::grazing_meets;
  q.met = at->sample.other_type;
  q.x = scaled.x(at->X);
  q.y = scaled.y(at->X);
  q.angle = at->sample.other_angle;
  return q;
}

// Where a fold or period-doubling curve reaches a 1:1 or 1:2 resonance between a and b: the
// second multiplier nearest the critical point (+1 or -1; within 0.1 of it at both) crosses the
// unit circle there, so |mu_2| - 1 changes sign. The curve ends there: past it the other
// multiplier is outside the circle and the curve bounds no stable region. (Before the corrector's
// tangent came from its points, a curve stopped there by failing, found by end_where_it_stops.)
// `closed` false: the bracket did not close (a trial point's correction failed: near the
// resonance the critical pair turns complex just off the curve), and the caller takes a shorter
// step: on milling_lobes_curves.toml a long step's bracket stopped at its end, 5 rpm and 1.2e-4 m
// short of where the Neimark-Sacker lobe ends.
std::optional<CurveState> reached_real_resonance(const ScaledCurve& scaled, const CurveState& a, const CurveState& b,
                                                 double tolerance, bool& closed) {
  closed = true;
  // (second_gap is set on fold and period-doubling curves only: NaN elsewhere)
  if (!(a.sample.second_gap < 0.1 && b.sample.second_gap < 0.1)) return std::nullopt;
  return sign_change_between(scaled, a, b, tolerance, &BoundarySample::second_side, closed);
}

// The last three points (scaled), their arclengths and angles, for the resonances passed.
struct ResonanceWatch {
  std::array<Vec2, 3> X{};
  std::array<double, 3> s{0, 0, 0}, angle{NAN, NAN, NAN};
  std::optional<Codim2Point> add(const Vec2& next, double next_angle, const ScaledCurve& scaled) {
    const double moved = norm({next[0] - X[2][0], next[1] - X[2][1]});
    X = {X[1], X[2], next};
    s = {s[1], s[2], s[2] + moved};
    angle = {angle[1], angle[2], next_angle};
    std::optional<Codim2Point> q = passed_resonance(X, s, angle);
    if (q) {
      const Vec2 at{q->x, q->y};
      q->x = scaled.x(at);
      q->y = scaled.y(at);
    }
    return q;
  }
};

}  // namespace

BoundaryCurve trace_boundary(const BoundaryFunction& g, double y_start, const BoundaryOptions& options,
                             const BoundaryFunction* at_points) {
  const BoundaryOptions& o = options;
  if (!std::isfinite(o.x_from) || !std::isfinite(o.x_to) || o.x_from == o.x_to)
    throw BadInput("boundary: the x range is empty or not finite");
  if (!std::isfinite(o.y_from) || !std::isfinite(o.y_to) || o.y_from == o.y_to)
    throw BadInput("boundary: the y range is empty or not finite");
  if (!(o.step > 0) || !(o.step_min > 0) || !(o.step_max >= o.step_min) || !(o.tolerance > 0))
    throw BadInput("boundary: steps and tolerance must be > 0, step_min <= step_max");
  if (o.max_points < 2) throw BadInput("boundary: max_points must be >= 2");

  BoundaryCurve curve;
  const ScaledCurve scaled(g, at_points, o, curve.evaluations);
  const auto add_point = [&](const CurveState& s) {
    curve.points.push_back({scaled.x(s.X), scaled.y(s.X), s.sample.angle, s.iterations});
  };
  CurveState current = start_of_curve(scaled, y_start, o);
  add_point(current);
  ResonanceWatch resonances;
  resonances.add(current.X, current.sample.angle, scaled);
  double ds = std::clamp(o.step, o.step_min, o.step_max);
  while (static_cast<int>(curve.points.size()) < o.max_points) {
    const Predictor p = predict(current, ds);
    ds = p.ds;
    std::string reason;
    std::optional<CurveState> next = next_point(scaled, current, p, o.tolerance, reason);
    if (!next) {
      ds *= 0.5;
      if (ds >= o.step_min) continue;
      end_where_it_stops(curve, scaled, current, reason);
      return curve;
    }
    bool closed = true;
    const std::optional<CurveState> resonance = reached_real_resonance(scaled, current, *next, o.tolerance, closed);
    if (!closed) {
      reason = "a second multiplier crosses the circle near the critical point, not located";
      ds *= 0.5;
      if (ds >= o.step_min) continue;
      end_where_it_stops(curve, scaled, current, reason);
      return curve;
    }
    if (std::optional<Codim2Point> q = met_other_curve(scaled, current, *next, o.tolerance)) curve.codim2.push_back(*q);
    if (const std::optional<CurveState>& at = resonance) {
      add_point(*at);
      const bool one_to_one = at->sample.other_type == BifurcationType::fold;
      Codim2Point q;
      q.kind = one_to_one ? Codim2Kind::resonance_1_1 : Codim2Kind::resonance_1_2;
      q.x = scaled.x(at->X);
      q.y = scaled.y(at->X);
      q.angle = at->sample.angle;
      curve.codim2.push_back(q);
      curve.end = BoundaryEnd::codim2;
      curve.note = std::string("a second multiplier reached ") + (one_to_one ? "+1" : "-1") + ": " + to_string(q) +
                   " at x = " + format_number(q.x) + ", y = " + format_number(q.y);
      return curve;
    }
    const Vec2 t_before = current.t;
    const double angle_before = current.sample.angle;
    current = *next;
    add_point(current);
    if (std::optional<Codim2Point> q = resonances.add(current.X, current.sample.angle, scaled)) curve.codim2.push_back(*q);
    if (p.landing != BoundaryEnd::max_points) {
      curve.end = p.landing;
      if (p.landing == BoundaryEnd::y_range)
        curve.note = "left the y range at x = " + format_number(curve.points.back().x) + ", y = " +
                     format_number(curve.points.back().y);
      return curve;
    }
    // The next step: the chord's sagitta, ds theta / 8 for a turn theta of the tangent over the
    // step ds, made chord_error (ds scaled by sqrt(chord_error / sagitta), within 0.5 .. 2); no
    // longer after a slow correction (>= 6 iterations: 0.7 ds).
    const double turn = std::acos(std::clamp(dot(t_before, current.t), -1.0, 1.0));
    const double sagitta = ds * turn / 8;
    double factor = sagitta > 0 ? std::clamp(std::sqrt(o.chord_error / sagitta), 0.5, 2.0) : 2.0;
    if (current.iterations >= 6) factor = std::min(factor, 0.7);
    // Within 0.1 of 0 or pi, a Neimark-Sacker curve's critical angle moves by at most 0.02 a
    // step: a strong resonance is located between points (passed_resonance's vertex, or where
    // the curve's definition ends), so its error is that of the points' spacing there. (With
    // the chord's steps alone the linear DDE's 1:2 resonance was off by 6e-3 in a; this test,
    // tests/cli/test_cli_boundary.cpp, wants 1e-3.)
    const double angle = current.sample.angle, moved = std::abs(angle - angle_before);
    if (current.sample.other_type == BifurcationType::neimark_sacker &&
        std::min(angle, std::numbers::pi - angle) < 0.1 && moved > 0.02)
      factor = std::min(factor, 0.02 / moved);
    ds = std::clamp(ds * factor, o.step_min, o.step_max);
  }
  curve.end = BoundaryEnd::max_points;
  curve.note = "after " + std::to_string(o.max_points) + " points";
  return curve;
}

BoundaryCurve trace_boundary_both_ways(const BoundaryFunction& g, const BoundaryOptions& whole, double x_start,
                                       double y_start, const BoundaryFunction* at_points) {
  const auto half = [&](double x_end) {
    BoundaryOptions o = whole;
    o.x_from = x_start;
    o.x_to = x_end;
    const double factor = std::abs(whole.x_to - whole.x_from) / std::abs(x_end - x_start);
    o.step *= factor, o.step_min *= factor, o.step_max *= factor, o.tolerance *= factor;
    return trace_boundary(g, y_start, o, at_points);
  };
  const double edge = 1e-12 * std::abs(whole.x_to - whole.x_from);
  const bool forward = std::abs(whole.x_to - x_start) > edge, backward = std::abs(x_start - whole.x_from) > edge;
  BoundaryCurve ahead = forward ? half(whole.x_to) : BoundaryCurve{};
  if (!backward || ahead.end == BoundaryEnd::from) return ahead;  // (closed: back at its start)
  BoundaryCurve behind = half(whole.x_from);
  if (!forward) return behind;
  // behind reversed, then ahead without its first point (the start, in both)
  BoundaryCurve joined = ahead;
  joined.points.assign(behind.points.rbegin(), behind.points.rend());
  joined.points.insert(joined.points.end(), ahead.points.begin() + 1, ahead.points.end());
  joined.codim2.insert(joined.codim2.begin(), behind.codim2.begin(), behind.codim2.end());
  joined.evaluations += behind.evaluations;
  if (behind.end == BoundaryEnd::failure || behind.end == BoundaryEnd::codim2) joined.end = behind.end;
  if (!behind.note.empty())
    joined.note = "towards " + format_number(whole.x_from) + ": " + behind.note +
                  (ahead.note.empty() ? "" : "; towards " + format_number(whole.x_to) + ": " + ahead.note);
  return joined;
}

bool on_boundary_curve(const std::vector<BoundaryCurve>& curves, double x, double y, double y_tolerance) {
  for (const BoundaryCurve& c : curves) {
    const size_t n = c.points.size();
    // The curve's extent: segments and turning angles are measured in the box it spans.
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (const BoundaryPoint& p : c.points) {
      x0 = std::min(x0, p.x), x1 = std::max(x1, p.x);
      y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
    }
    const double wx = x1 > x0 ? x1 - x0 : 1, wy = y1 > y0 ? y1 - y0 : 1;
    const auto segment = [&](size_t i) {  // points i - 1 -> i, in the box
      return Vec2{(c.points[i].x - c.points[i - 1].x) / wx, (c.points[i].y - c.points[i - 1].y) / wy};
    };
    const auto turn = [&](const Vec2& a, const Vec2& b) {  // the angle between two segments
      const double na = norm(a), nb = norm(b);
      return na > 0 && nb > 0 ? std::acos(std::clamp(dot(a, b) / (na * nb), -1.0, 1.0)) : 0.0;
    };
    for (size_t i = 1; i < n; ++i) {
      const BoundaryPoint &a = c.points[i - 1], &b = c.points[i];
      if ((x - a.x) * (x - b.x) > 0 || a.x == b.x) continue;
      const double y_here = a.y + (b.y - a.y) * (x - a.x) / (b.x - a.x);
      // The curve leaves the chord by at most about its sagitta, length x turning angle / 4 (the
      // turn at either end of the segment): a chord across a sharp lobe bottom misses the curve
      // by far more than y_tolerance.
      const Vec2 s = segment(i);
      double angle = 0;
      if (i >= 2) angle = std::max(angle, turn(segment(i - 1), s));
      if (i + 1 < n) angle = std::max(angle, turn(s, segment(i + 1)));
      const double sagitta = norm(s) * angle / 4 * wy;
      if (std::abs(y_here - y) <= y_tolerance + sagitta) return true;
    }
  }
  return false;
}

BoundaryPointStudy boundary_point_study(const BoundaryCurve& curve, size_t k, const std::vector<BoundaryFunction>& coarser,
                                        const std::vector<int>& Ns, const BoundaryOptions& scale,
                                        const RichardsonOptions& richardson, const BoundaryPointStudy* previous,
                                        const std::vector<BoundaryFunction>& finer, const std::vector<int>& finer_Ns) {
  BoundaryPointStudy s;
  const size_t n = curve.points.size();
  const BoundaryPoint& pt = curve.points.at(k);
  const double dx = scale.x_to - scale.x_from, dy = scale.y_to - scale.y_from;  // (scaled unit -> physical)
  // The unit normal in the scaled plane, from the neighbours (one-sided at the ends).
  const BoundaryPoint& a = curve.points[k > 0 ? k - 1 : k];
  const BoundaryPoint& b = curve.points[k + 1 < n ? k + 1 : k];
  const double tu = (b.x - a.x) / dx, tv = (b.y - a.y) / dy, length = std::hypot(tu, tv);
  const double nu = length > 0 ? -tv / length : 0, nv = length > 0 ? tu / length : 1;
  std::vector<double> offset_by_N;  // per level of s.levels, NaN where not found
  const auto add_level = [&](int N, double offset) {
    s.levels.push_back(N);
    s.x_by_N.push_back(pt.x + offset * nu * dx);
    s.y_by_N.push_back(pt.y + offset * nv * dy);
    offset_by_N.push_back(offset);
  };
  for (size_t i = 0; i < Ns.size(); ++i) {
    double offset = 0;  // (the finest N: the point itself)
    if (i < coarser.size()) {
      // The previous point's point of this level's curve, projected on this point's normal
      const double guess = previous && i < previous->x_by_N.size()
                               ? (previous->x_by_N[i] - pt.x) / dx * nu + (previous->y_by_N[i] - pt.y) / dy * nv
                               : NAN;
      offset = boundary_offset_along(coarser[i], pt.x, pt.y, nu * dx, nv * dy, 1e-6, scale.tolerance, guess);
    }
    add_level(Ns[i], offset);
  }
  // The levels from `first` on, extrapolated (Richardson in h = 1 / N); nothing without two
  // levels or an estimate.
  const auto extrapolate = [&](size_t first) -> std::optional<std::pair<Extrapolation, std::vector<int>>> {
    std::vector<double> h;
    std::vector<std::complex<double>> offsets;
    std::vector<int> used;
    for (size_t l = first; l < s.levels.size(); ++l)
      if (std::isfinite(offset_by_N[l])) {
        h.push_back(1.0 / s.levels[l]);
        offsets.push_back(offset_by_N[l]);
        used.push_back(s.levels[l]);
      }
    if (offsets.size() < 2) return std::nullopt;
    Extrapolation e = richardson_extrapolate(h, offsets, richardson);
    if (!std::isfinite(e.error_estimate)) return std::nullopt;
    return std::pair{std::move(e), std::move(used)};
  };
  auto result = extrapolate(0);
  // Pre-asymptotic levels: no estimate, or one above the next coarser level's offset (the
  // extrapolation less sure than the curve's own N, which the offset bounds), as at a lobe's cusp,
  // narrower at the coarsest N than the offsets between the levels. There the levels `finer` are
  // added one by one, each dropping the coarsest, and kept if it shows the order with a smaller
  // estimate. (At a flip lobe's tip even N = 200 may have no flip lobe on the normal of the N = 400
  // curve: 2N and 4N, both wider there, give the point its estimate.)
  if (Ns.size() >= 3) {
    const double own = std::abs(offset_by_N[Ns.size() - 2]);
    for (size_t f = 0; f < finer.size() && (!result || !(result->first.error_estimate <= own)); ++f) {
      add_level(finer_Ns.at(f), boundary_offset_along(finer[f], pt.x, pt.y, nu * dx, nv * dy, 1e-6, scale.tolerance));
      auto refined = extrapolate(f + 1);
      if (refined && (!result || refined->first.error_estimate < result->first.error_estimate))
        result = std::move(refined);
    }
  }
  if (!result) return s;
  const Extrapolation& e = result->first;
  s.extrapolated_from = result->second;
  // Each offset is known to the location tolerance (the secant's last step; the finest N's 0 to
  // the corrector's), and the extrapolation adds them with weights of sum ~1.5 (h^2 .. h^6
  // eliminated, step ratio 2): the estimate never goes below 2 tolerances. Without this floor a
  // curve located to 1e-10 claimed 2e-12 for an error of 1.6e-10 (the exact grazing curve,
  // tests/cli/test_cli_boundary.cpp). Passed to the tableau as input errors instead, the
  // tolerance (a bound, far above the secant's actual accuracy) would read as a plateau.
  const double estimate = std::max(e.error_estimate, 2 * scale.tolerance);
  const double offset = e.value.real();
  s.x_extrapolated = pt.x + offset * nu * dx;
  s.y_extrapolated = pt.y + offset * nv * dy;
  s.x_error_estimate = estimate * std::abs(nu * dx);
  s.y_error_estimate = estimate * std::abs(nv * dy);
  return s;
}

double boundary_offset_along(const BoundaryFunction& g, double x, double y, double dx, double dy, double step,
                             double tolerance, double guess) {
  const auto at = [&](double s) { return g(x + s * dx, y + s * dy); };
  // From the point itself, the secant's second point the guess: the root nearest the point, found
  // in few steps where the guess is good. (Started from the guess, a root of another part of a
  // coarser curve, met where the normal crosses it twice near a lobe's bottom, was carried on
  // from point to point.) Where g is undefined at the point, from the guess.
  double s0 = 0, s1 = std::isfinite(guess) && std::abs(guess) > step ? guess : step;
  BoundarySample g0 = at(s0);
  if (!g0.defined && std::isfinite(guess) && (g0 = at(guess)).defined) {
    s0 = guess;
    s1 = guess + step;
  }
  // Undefined at the point itself: the secant starts instead from the nearest point of the line
  // where g is defined, searched on both sides at 10 step 4^k up to kReach. The case: a coarser
  // level's flip lobe is narrower, so at points of the finest curve the coarser level's critical
  // pair has not yet split on the real axis, and the period-doubling test needs a real multiplier.
  // On the lobe diagram of milling_lobes_curves.toml this left a quarter of the offsets to the
  // coarser curves undefined, and most flip-lobe points without an error estimate. kReach (0.4 % of
  // the scaled plane) is some ten times the offsets between the levels there, far
  // below the distance to another lobe; a wrong root would fail the extrapolation's order check.
  constexpr double kReach = 4e-3;
  for (double d = 10 * step; !g0.defined && d <= kReach; d *= 4)
    for (double side : {1.0, -1.0}) {
      if ((g0 = at(side * d)).defined) {
        s0 = side * d;
        s1 = s0 + side * step;
        break;
      }
    }
  if (!g0.defined) return NAN;
  // The secant converges superlinearly: on the lobe diagram of milling_lobes_curves.toml 1250 of
  // 1380 searches ended in 3-6 evaluations, the slowest that converged in 18. One not converged
  // in 20 steps cycles or drifts (there 80 ran to the former limit, 30, each to NaN: a third of
  // the error bars' evaluations). Where g keeps its sign for 14 steps the line misses the curve
  // (a coarser lobe's narrower tip: g has a maximum below 0 on the line, and the secant wanders
  // around it): NaN then too.
  bool crossed = false;  // g of both signs seen
  for (int it = 0; it < 20 && (crossed || it < 14); ++it) {
    BoundarySample g1 = at(s1);
    // A secant step into where g is undefined (the same pair, not yet split): halved back toward
    // the last defined point, down to a millionth of it.
    for (int half = 0; !g1.defined && half < 20; ++half) g1 = at(s1 = s0 + (s1 - s0) / 2);
    if (!g1.defined || g1.value == g0.value) return NAN;
    crossed = crossed || (g1.value > 0) != (g0.value > 0);
    const double s2 = s1 - g1.value * (s1 - s0) / (g1.value - g0.value);
    if (!std::isfinite(s2)) return NAN;
    if (std::abs(s2 - s1) <= tolerance) return s2;
    s0 = s1;
    g0 = g1;
    s1 = s2;
  }
  return NAN;
}

}  // namespace delayspec
