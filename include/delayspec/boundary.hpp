#pragma once
// Stability boundaries as curves in two parameters (issue 36): the set where the critical
// multiplier of one bifurcation type is on its condition, g(x, y) = 0, g the type's test function
// (continuation.hpp: fold mu - 1 of the real positive multiplier nearest 1; period doubling
// |mu| - 1 of the real negative one nearest -1; Neimark-Sacker |mu| - 1 of the non-real one
// nearest the unit circle; grazing max H), evaluated on the periodic orbit solved at (x, y): the
// extended system F(u; x, y) = 0, g = 0 in its nested form (the periodic problem solved inside,
// the critical condition outside). The caller supplies g (BoundaryFunction): the library follows
// its zero set.
//
// The curve, in the scaled plane X = (u, v) = ((x - x_from) / |x_to - x_from|, (y - y_from) /
// |y_to - y_from|), by pseudo-arclength: predictor X_i + ds t_i along the unit tangent t_i (grad
// g turned by 90 degrees, oriented along the curve: <t_new, t_old> > 0, the first toward x_to);
// corrector Newton (the chord form: grad g at the last accepted point) on
//
//   g(X) = 0,   <t_i, X - X_pred> = 0,
//
// converged when the correction is <= tolerance, the chord's row updated by Broyden's rule. No
// evaluation beyond the corrector's per point: the tangent at a new point from the quadratic
// through the last three points (second-order in the step), the gradient the corrector's row
// turned normal to it (a point satisfies g = 0 whatever the gradient; it only sets the
// corrector's contraction). At the start, grad g by forward differences with delta = 1e-7 in
// the scaled plane (g, an eigenvalue modulus accurate to ~1e-12, gives it to ~1e-5).
// Bordered by the arclength condition the system stays regular where the curve turns in x, so
// turning points are passed (x goes back). Step control by the chord: the next step is this one
// times sqrt(chord_error / sagitta) (within 0.5 .. 2), the sagitta ds theta / 8 from the
// tangent's turn theta over the step, so the polyline stays within chord_error of the curve; at
// most 0.7 of it after >= 6 iterations; within 0.1 of 0 or pi a Neimark-Sacker curve's angle moves
// by at most 0.02 a step (a strong resonance between close points). A failure (not converged in
// 8 iterations, g undefined: no multiplier of the type, the orbit or eigensolver failing; a
// tangent turning by more than ~37 degrees; a corrected point farther from its predictor than the
// step, or outside the ranges) halves the step; below step_min the curve ends.
//
// Ends: at x_to exactly (the predictor shortened to land there, the last point corrected with x
// fixed); back at x_from after a turn (likewise); where it leaves the y range [y_from, y_to]
// (the point on the range's edge); at a codim-2 point where a Neimark-Sacker curve's critical
// pair reaches the real axis (angle 0: 1:1 resonance, angle pi: 1:2 resonance, meeting a fold or
// period-doubling curve), found as the end of the curve's definition with the last angle within
// 0.05 rad of 0 or pi; on a fold or period-doubling curve at a 1:1 or 1:2 resonance, where a
// second multiplier near +1 or -1 (second_gap < 0.1) crosses the unit circle between two points
// (second_side changes sign), located on the curve like a meeting below and made the last point,
// or found as the curve's end with a second multiplier within 0.05 of +1 or -1; after max_points;
// or at a failure (step below step_min), named.
//
// Where a grazing curve meets a stability curve (a codim-2 point the curve passes, not an end):
// found on either curve by the sign change, between two accepted points, of the other kind's test
// function (BoundarySample::other: max H on a stability curve, |mu_1| - 1 of the leading
// multiplier on a grazing curve), then located on the curve by regula falsi (Illinois) in the
// position along the chord between them, each trial point corrected onto the curve across the
// chord, to the curve's tolerance.
#include <complex>
#include <functional>
#include <string>
#include <vector>

#include "delayspec/continuation.hpp"
#include "delayspec/richardson.hpp"

namespace delayspec {

// The test function at one point.
struct BoundarySample {
  bool defined = false;  // an orbit and a critical multiplier of the type exist there
  double value = NAN;    // g
  double angle = NAN;    // arg of the critical multiplier, in [0, pi] (grazing: NaN)
  std::string reason;    // why not defined
  // The other kind's test function, whose zero on the curve is where it meets a curve of the
  // other kind: on a stability curve max H (the orbit starts to touch the switching surface: NaN
  // for a model without one), on a grazing curve |mu_1| - 1 (the grazing orbit's leading
  // multiplier mu_1 on the unit circle: NaN when no multipliers were computed); other_type is the
  // stability curve's type: the curve's own, or the type mu_1 crosses as (continuation.hpp's
  // crossing_type), and other_angle |arg| of that multiplier.
  double other = NAN;
  BifurcationType other_type = BifurcationType::grazing;
  double other_angle = NAN;
  // On a fold or period-doubling curve: the distance from the next multiplier to the critical
  // point (+1 or -1). Small where a second real multiplier meets the critical one there, the 1:1
  // or 1:2 resonance such a curve can end at (its angle is 0 or pi everywhere, so says nothing).
  double second_gap = NAN;
  double second_side = NAN;  // |mu| - 1 of that next multiplier: its sign changes where it crosses
};
using BoundaryFunction = std::function<BoundarySample(double x, double y)>;

// The test function of `type` from the leading multipliers (and max H for grazing): what
// continuation locates (continuation_detail::multiplier_test); with the other kind's test function
// (max H, or |mu_1| - 1 when multipliers are given for a grazing curve).
BoundarySample boundary_sample(BifurcationType type, const std::vector<std::complex<double>>& multipliers,
                               double max_H);

struct BoundaryOptions {
  double x_from = 0, x_to = 1;  // the curve starts at x_from and ends at x_to
  double y_from = 0, y_to = 1;  // the y range the curve stays in
  double step = 0.02;           // initial arclength step in the scaled plane
  double step_min = 1e-6, step_max = 0.1;
  int max_points = 1000;
  double tolerance = 1e-10;  // of a point, in the scaled plane
  double chord_error = 1e-4;  // the curve's distance from the chord between two points (step control)
};

struct BoundaryPoint {
  double x = 0, y = 0;
  double angle = NAN;  // the critical multiplier's
  int iterations = 0;  // corrector iterations
};

enum class BoundaryEnd { to, from, y_range, codim2, max_points, failure };
// "to", "from", "y_range", "codim2", "max_points", "failure".
std::string to_string(BoundaryEnd end);

// Where a curve changes character: a Neimark-Sacker curve whose pair reaches 1 (angle 0) or -1
// (angle pi), or a grazing curve meeting a stability curve.
enum class Codim2Kind { resonance_1_1, resonance_1_2, grazing_meets };

struct Codim2Point {
  Codim2Kind kind = Codim2Kind::resonance_1_1;
  BifurcationType met = BifurcationType::fold;  // grazing_meets: the stability curve's type
  double x = 0, y = 0, angle = 0;               // angle: the critical multiplier's |arg| there
};
// "1:1 resonance", "1:2 resonance", "grazing meets TYPE" (TYPE the stability curve's: fold,
// period-doubling, neimark-sacker): the JSON's and the text's words.
std::string to_string(const Codim2Point& point);

struct BoundaryCurve {
  std::vector<BoundaryPoint> points;
  BoundaryEnd end = BoundaryEnd::max_points;
  std::string note;  // where and why it ended (y_range, failure, codim2)
  std::vector<Codim2Point> codim2;
  long evaluations = 0;  // of g
};

// The curve of g = 0 from (x_from, y_start), g(x_from, y_start) = 0 to the tolerance (the caller
// located it). BadInput: an empty range, a step <= 0, step_min > step_max, max_points < 2;
// NumericalFailure: g undefined at the start, or the start not on the curve (|correction| above
// 1e-6 of the range).
// `at_points`, when given: the test function at the curve's own points (each accepted point, and
// each located on it), in place of g there: g with what only those points need (a grazing curve's
// multipliers, for BoundarySample::other), never evaluated for gradients or corrector iterations.
BoundaryCurve trace_boundary(const BoundaryFunction& g, double y_start, const BoundaryOptions& options,
                             const BoundaryFunction* at_points = nullptr);

// The curve through (x_start, y_start), a point on it with x_start in [x_from, x_to] of `whole`:
// traced from there to x_to and, when it starts inside the range, also back to x_from, the two
// halves joined (x_from's half reversed; the curve's end and note are the worse half's, a failure
// or a resonance before a range's edge). Steps and tolerance are those of the whole range's scaled
// plane. A curve that comes back to its start (closed) is traced once.
BoundaryCurve trace_boundary_both_ways(const BoundaryFunction& g, const BoundaryOptions& whole, double x_start,
                                       double y_start, const BoundaryFunction* at_points = nullptr);

// Whether (x, y) lies on one of the curves: within `y_tolerance` of a segment's y at that x.
bool on_boundary_curve(const std::vector<BoundaryCurve>& curves, double x, double y, double y_tolerance);

// A point of a curve against the curves of coarser N (`coarser[i]`: the test function at Ns[i],
// Ns increasing, the last the curve's own): each found on the line through the point along the
// curve's normal in the plane scaled by `scale`'s ranges (boundary_offset_along: well conditioned
// whether the curve is flat or steep), the offsets extrapolated to N -> infinity (Richardson in
// h = 1 / N), and the extrapolated point with its error estimate in x and in y (the estimate along
// the normal, projected), never below twice `scale.tolerance` (a point and each level's offset
// are located to it). NaN where the levels do not show their order or a level finds no curve.
struct BoundaryPointStudy {
  std::vector<int> levels;             // the N of each entry below: Ns, then those of `finer` studied
  std::vector<double> x_by_N, y_by_N;  // the point of each level's curve on the normal (Ns.back(): the point)
  std::vector<int> extrapolated_from;  // the levels the extrapolation used (empty: none)
  double x_extrapolated = NAN, y_extrapolated = NAN;
  double x_error_estimate = NAN, y_error_estimate = NAN;
};
// `previous`: the study of the point before (k - 1), whose points of the coarser curves, projected
// on this point's normal, are each search's guess (a curve's neighbouring points have their
// coarser curves at nearly the same offsets).
// `finer`: the test functions at the levels finer_Ns, increasing from above Ns.back(), studied
// (with three levels Ns or more) one after the other only while the levels so far are
// pre-asymptotic: no estimate, or one above the next coarser level's offset (the extrapolation
// less sure than the curve's own N, which that offset bounds). Each adds its level and drops the
// coarsest (Ns[1..] and finer_Ns[0], then Ns[2..] and finer_Ns[0..1], ...); an extrapolation is
// kept where it has an estimate smaller than the one before.
BoundaryPointStudy boundary_point_study(const BoundaryCurve& curve, size_t k, const std::vector<BoundaryFunction>& coarser,
                                        const std::vector<int>& Ns, const BoundaryOptions& scale,
                                        const RichardsonOptions& richardson,
                                        const BoundaryPointStudy* previous = nullptr,
                                        const std::vector<BoundaryFunction>& finer = {},
                                        const std::vector<int>& finer_Ns = {});

// The s with g((x, y) + s (dx, dy)) = 0 nearest 0, by the secant method from s = 0 and s = guess
// (NaN: step), to |ds| <= tolerance. Where g is undefined at 0, from s = guess and guess + step;
// where it is undefined there too (or no guess), from the nearest s within 4e-3 where it is
// defined; a step into where it is undefined is halved back. NaN when it does not converge in 20
// secant steps or g stays undefined. Along the curve's normal (another N's curve near a point of
// this one) the secant is well conditioned wherever the curve goes, steep or flat.
double boundary_offset_along(const BoundaryFunction& g, double x, double y, double dx, double dy, double step,
                             double tolerance, double guess = NAN);

}  // namespace delayspec
