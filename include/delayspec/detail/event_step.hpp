#pragma once
// One full step of the trapezoid rule split at the events inside it (design.md 1.5, the paper's
// Section 4 as corrected in paper/ERRATA.md items 2-7), and its exact derivative.
//
// The step from t to t + h is a sequence of pieces [a, b] (offsets from t), each with an
// explicit region j used at every node of the piece; consecutive pieces are separated by an
// event, a zero of H. A piece on the H > 0 side (region 1, contact) is integrated with
// m = contact_substeps equal trapezoid sub-steps, a piece in region 2 with one:
//
//   z_i = z_{i-1} + L/2 [ f_j(t + s_{i-1}, z_{i-1}, w(s_{i-1})) + f_j(t + s_i, z_i, w(s_i)) ],
//   s_i = a + i (b - a) / m,   L = (b - a) / m,   w(s) = (1 - s/h) w0 + (s/h) w1,
//
// where w0 = y_tau(t), w1 = y_tau(t + h): the delayed value inside the step is the linear
// interpolant of the two history blocks the step map already uses (ERRATA 4). Only u_0 moves;
// the history shifts once per full step (ERRATA 3), so the composed step map is again
// du_0(t + h) = P du_0 + Q dw0 + R dw1.
//
// Event times (key `events`):
//   on:     b solves H(z_b(b)) = 0 exactly for the discrete piece (z_b = the piece's result as a
//           function of its end b), by a bracketed root finder (Brent) to machine precision;
//   linear: the paper's estimates, corrected (ERRATA 6): from a point strictly inside a region
//           b = a - H / H' (first order); from a point on H = 0 (a contact that ends inside the
//           step) b = a - 2 H' / H'' (the second zero of the quadratic Taylor polynomial).
// H' and H'' are the time derivatives of H along the vector field of the piece's region.
//
// Detection, per piece starting at a in region j: (1) H at the piece's trial end (b = h) is on
// the other side: an exit inside (a, h] (paper's case 1); (2) the same side at both ends: a
// grazing excursion (case 2) is looked for when the cubic Hermite interpolant of H(z(s)) on
// [a, h] (values and slopes H' at both ends) has an interior extremum that comes within
// `margin` = |slope change| * L of H = 0 (a minimum of into H, or for a piece that starts on
// H = 0 either kind: hermite_extremum_within); then the true extremum of H(z(s)) is located (Brent's
// minimiser) and, if it lies beyond H = 0 by more than a few hundred ulps, the step is split at
// the two zeros. Why nothing is missed for small h: H(z(s)) is smooth on a piece, and the
// Hermite cubic matches it to O(L^4 max|H''''|); a turning point of H inside the step changes
// the slope by ~L |H''|, so for small L every excursion that reaches H = 0 has a Hermite
// extremum within O(L^4) << margin ~ L^2 |H''| of it and triggers the exact search. Two turning
// points in one step need H'' to change sign within L: the excursion between them is then
// O(L^3) deep and its effect on the step below the local error. Excursions shallower than the
// threshold (256 eps (1 + |z|) |grad H|) are ignored: a contact that shallow changes the step
// by O(beta p^(3/2)) with p <= 1e-13, far below rounding of the result.
//
// Step map (key `jacobian`):
//   consistent: the exact derivative of the discrete step, including how the event times move
//               with (u0, w0, w1): for `on`, implicit differentiation of H(z_b) = 0 gives
//               db = -grad H . X / grad H . Y where dz_b = X + Y db (X: derivative at fixed b,
//               Y = dz_b/db); for `linear`, the derivative of the estimate formula;
//   frozen:     the paper's: split points held fixed (db = 0). Not the derivative of the
//               discrete map; near grazing its error is O(1) (ERRATA 7).
// Forward-mode tangents: each node carries dz (d x 3d, columns u0, w0, w1) and ds (1 x 3d).
//
// Conventions at degenerate points. H(u0) = 0 exactly counts as region 2 (model.hpp); a
// trajectory leaving it upwards gets a zero-length region-2 piece and an event at s = 0, so the
// step map is the limit from the H < 0 side. The discrete map is continuous but only one-sided
// differentiable where an event enters or leaves a step through one of its ends (its
// derivative jumps by O(h^2 |A_1 - A_2|)), and at the onset of grazing (the split itself
// changes the trapezoid's O(h^3) local error).
//
// Cost: a step with no event and no near-surface turning point is the plain trapezoid step
// (m sub-steps in contact) plus the event test (H and its slope at both ends); an event costs
// ~10-60 piece evaluations.
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/LU>

#include "delayspec/detail/cubic_hermite.hpp"
#include "delayspec/detail/small_solve.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/model.hpp"
#include "delayspec/detail/scalar_search.hpp"
#include "delayspec/step_map.hpp"
#include "delayspec/step_options.hpp"

namespace delayspec {

template <class Model>
class TrapezoidStepper;  // stepper.hpp: its sub_step() and options() are what a split step uses

namespace detail {

// The cubic Hermite polynomial p on [0, 1] (scaled time tau) with p(0) = ga, p(1) = gL,
// p'(0) = d0, p'(1) = d1: does it have an interior extremum where into * p < margin?
// (into = +1 or -1: the side of H = 0 the piece is on; EventStepSolver::excursion_suspected.)
// With minima_only, only the minima of into p count: for a piece whose ends are both strictly
// inside, an excursion is a minimum of into H, and one the cubic shows as a maximum would need
// three turning points in the step (up, down and out, back in, down to the end), which the
// header's argument already leaves out. A piece starting on the surface (after an event) keeps
// the maxima: out again and back in by its end is only two turning points away from the one the
// cubic shows (test_events_hard_cases, StiffContactBetaTenThousand). Measured: in the shallow
// contacts of the paper's orbits (depth ~ 1e-4, the margin's size) maxima were 99 % of the
// suspicions, each an exact search of ~37 piece evaluations that found nothing.
inline bool hermite_extremum_within(double ga, double gL, double d0, double d1, double margin, double into,
                                    bool minima_only = false) {
  // Most steps are far from H = 0: skip the roots (a sqrt and two divisions, measured a third
  // of the event test) when the whole cubic is beyond the margin. p(tau) = chord(tau) +
  // tau (1 - tau) [(1 - tau) (d0 - D) - tau (d1 - D)], D = gL - ga, so |p - chord| <=
  // max(|d0 - D|, |d1 - D|) / 4 on [0, 1] and into p >= into min(ga, gL) - that bound there;
  // if this exceeds the margin, no extremum is within it and the roots below would answer no.
  // The slack (1e-12 of the data) is far above their own rounding (~10 eps of it).
  const double chord_deviation = 0.25 * std::max(std::abs(d0 - (gL - ga)), std::abs(d1 - (gL - ga)));
  const double slack = 1e-12 * (std::abs(ga) + std::abs(gL) + std::abs(d0) + std::abs(d1));
  if (std::min(into * ga, into * gL) - chord_deviation > margin + slack) return false;
  const CubicHermite p(ga, gL, d0, d1);
  double roots[2];
  const int n = p.turning_points(roots);
  for (int i = 0; i < n; ++i) {
    const double tau = roots[i];
    if (!(tau > 0 && tau < 1)) continue;
    if (minima_only && into * p.half_curvature(tau) < 0) continue;  // a maximum of into p
    if (into * p(tau) < margin) return true;
  }
  return false;
}

template <class Model>
class EventStepSolver {
 public:
  static constexpr int D = Model::d;
  static constexpr int DW = delayed_rows<Model>;  // D, or D n with n delays (model.hpp)
  using V = Vec<D>;
  using W = DelayedVec<Model>;  // the delayed values (stacked with several delays)
  using M = Mat<D>;
  using BM = DelayedMat<Model>;  // df / dw
  using Tangent = Eigen::Matrix<double, D, D + 2 * DW>;  // d(.)/d(u0, w0, w1)
  using Row = Eigen::Matrix<double, 1, D + 2 * DW>;

  EventStepSolver(const TrapezoidStepper<Model>& stepper, double t, double h, const W& w0, const W& w1)
      : stepper_(stepper), model_(stepper.model()), options_(stepper.options()), t_(t), h_(h), w0_(w0), w1_(w1) {
    static_assert(
        requires(const Model& m, V y) {
          { m.f_t(1, 0.0, y, W()) } -> std::convertible_to<V>;
          { m.f_tt(1, 0.0, y, W()) } -> std::convertible_to<V>;
        },
        "a model with switching must provide f_t and f_tt (model.hpp)");
    wdot_ = (w1 - w0) / h;
  }

  V run(const V& u0, StepLinearisation<D, DW>& linearisation, StepEvents* events) const {
    double a = 0;
    V z = u0;
    int j = region_of(model_, u0);
    Tangent dz = Tangent::Zero();
    dz.template leftCols<D>().setIdentity();
    Row da = Row::Zero();
    int count = 0;
    for (;;) {
      const int m = substeps(j);
      Exit exit;
      if (count == 0) {
        // Most steps have no event: the trial piece over the whole step, with the derivative of
        // its end at fixed ends (da = db = 0), is then the step and its map.
        if (m == 1) {  // one sub-step: the plain trapezoid step in region j, its derivative factored
          int jr;
          const V z1 = stepper_.factored_sub_step(t_, h_, u0, w0_, w1_, j, j, linearisation.sub, jr);
          exit = find_exit(0, u0, z1, j, false);
          if (!exit.event) {
            if (events) events->count = 0;
            linearisation.factored = true;
            return z1;
          }
        } else {
          const Piece whole = piece_with_fixed_ends(0, h_, u0, dz, j, m);
          exit = find_exit(0, u0, whole.z, j, false);
          if (!exit.event) {
            z = whole.z;
            dz = whole.X;
            break;
          }
        }
      } else {
        if (a < h_) exit = find_exit(a, z, piece_end(a, h_, z, j, m), j, true);
      }
      const double b = exit.event ? exit.b : h_;
      const Piece piece = piece_with_tangent(a, b, z, dz, da, j, m);
      Row db = Row::Zero();  // the end of the step (b = h) and frozen split points do not move
      if (exit.event && options_.jacobian == JacobianMode::consistent) {
        if (options_.events == EventMode::on || exit.clamped) {
          if (options_.events == EventMode::on) db = implicit_event_time_derivative(piece, b);
        } else {
          db = linear_event_time_derivative(a, z, dz, da, j, exit.from_surface);
        }
      }
      dz = piece.X + piece.Y * db;  // dz_b = X + Y db
      da = db;
      z = piece.z;
      a = b;
      if (!exit.event) break;
      if (count == StepEvents::kMaxEvents)
        throw NumericalFailure("event step at t = " + format_number(t_) + ", h = " + format_number(h_) +
                               ": more than " + std::to_string(StepEvents::kMaxEvents) +
                               " events in one step (reduce h)");
      j = 3 - j;
      if (events) {
        events->offset[count] = b;
        events->new_region[count] = j;
      }
      ++count;
    }
    if (events) events->count = count;
    linearisation.factored = false;
    linearisation.map.P = dz.template leftCols<D>();
    linearisation.map.Q = dz.template middleCols<DW>(D);
    linearisation.map.R = dz.template rightCols<DW>();
    return z;
  }

 private:
  struct Exit {
    bool event = false;
    double b = 0;
    bool from_surface = false;  // the piece started on H = 0 (after an earlier event)
    bool clamped = false;       // events = linear: the estimate was clamped to the piece
  };
  struct Piece {
    V z;        // the piece's end state
    Tangent X;  // dz_b at fixed end time b
    V Y;        // dz_b / db
  };

  int substeps(int j) const { return j == 1 ? options_.contact_substeps : 1; }
  W w_at(double s) const { return (1 - s / h_) * w0_ + (s / h_) * w1_; }
  static double node(double a, double b, int m, int i) { return i == m ? b : a + (b - a) * i / m; }
  double threshold(const V& z) const {
    return 256 * std::numeric_limits<double>::epsilon() * (1 + z.template lpNorm<Eigen::Infinity>()) *
           (model_.grad_H(z).template lpNorm<Eigen::Infinity>());
  }

  // The piece [a, b] in region j with m sub-steps, values only.
  V piece_end(double a, double b, const V& za, int j, int m) const {
    V z = za;
    for (int i = 1; i <= m; ++i) {
      const double s0 = node(a, b, m, i - 1), s1 = node(a, b, m, i);
      z = stepper_.sub_step_state(t_ + s0, s1 - s0, z, w_at(s0), w_at(s1), j, j);
    }
    return z;
  }

  // The same piece with the derivative of its end at fixed a and b (X; Y is left zero): the
  // chain of the sub-steps' own maps, the delayed value at node s being w(s). It equals
  // piece_with_tangent's X when da = 0, at the cost of plain sub-steps.
  Piece piece_with_fixed_ends(double a, double b, const V& za, const Tangent& dza, int j, int m) const {
    Piece p{za, dza, V::Zero()};
    for (int i = 1; i <= m; ++i) {
      const double s0 = node(a, b, m, i - 1), s1 = node(a, b, m, i);
      const SubStepResult<D, DW> r = stepper_.sub_step(t_ + s0, s1 - s0, p.z, w_at(s0), w_at(s1), j, j);
      Tangent X = r.dz0 * p.X;
      X.template middleCols<DW>(D) += (1 - s0 / h_) * r.dw0 + (1 - s1 / h_) * r.dw1;
      X.template rightCols<DW>() += (s0 / h_) * r.dw0 + (s1 / h_) * r.dw1;
      p.X = X;
      p.z = r.z1;
    }
    return p;
  }

  // The same piece with forward-mode tangents. Node s_i = (1 - c_i) a + c_i b, c_i = i/m, so
  // ds_i = (1 - c_i) da + c_i db; the db part is carried separately in Y (db is not known
  // until the event condition at the piece's end is differentiated).
  Piece piece_with_tangent(double a, double b, const V& za, const Tangent& dza, const Row& da, int j, int m) const {
    Piece p{za, dza, V::Zero()};
    for (int i = 1; i <= m; ++i) {
      const double s0 = node(a, b, m, i - 1), s1 = node(a, b, m, i), L = s1 - s0;
      const double c0 = static_cast<double>(i - 1) / m, c1 = static_cast<double>(i) / m;
      const W wl = w_at(s0), wr = w_at(s1);
      const V zl = p.z;
      const V zr = stepper_.sub_step_state(t_ + s0, L, zl, wl, wr, j, j);
      const double tl = t_ + s0, tr = t_ + s0 + L;
      const V fl = model_.f(j, tl, zl, wl), fr = model_.f(j, tr, zr, wr);
      const M Al = model_.A(j, tl, zl, wl), Ar = model_.A(j, tr, zr, wr);
      const BM Bl = model_.B(j, tl, zl, wl), Br = model_.B(j, tr, zr, wr);
      const V ftl = model_.f_t(j, tl, zl, wl), ftr = model_.f_t(j, tr, zr, wr);
      const detail::SmallSolve<D> lu(M(M::Identity() - 0.5 * L * Ar));  // S = I - L/2 A_r
      const M Jz = lu.solve(M(M::Identity() + 0.5 * L * Al));           // dz_i/dz_{i-1}
      // dz_i/ds_{i-1} and dz_i/ds_i: the length changes by -1/+1, the node's time and delayed
      // value move with it (d/ds f(t + s, z, w(s)) = f_t + B w').
      const V Js0 = lu.solve(V(-0.5 * (fl + fr) + 0.5 * L * (ftl + Bl * wdot_)));
      const V Js1 = lu.solve(V(0.5 * (fl + fr) + 0.5 * L * (ftr + Br * wdot_)));
      // dz_i/dw0, dz_i/dw1 through w(s_{i-1}) and w(s_i)
      const BM Jw0 = lu.solve(BM(0.5 * L * (Bl * (1 - s0 / h_) + Br * (1 - s1 / h_))));
      const BM Jw1 = lu.solve(BM(0.5 * L * (Bl * (s0 / h_) + Br * (s1 / h_))));
      Tangent X = Jz * p.X + Js0 * ((1 - c0) * da) + Js1 * ((1 - c1) * da);
      X.template middleCols<DW>(D) += Jw0;
      X.template rightCols<DW>() += Jw1;
      p.Y = Jz * p.Y + Js0 * c0 + Js1 * c1;
      p.X = X;
      p.z = zr;
    }
    return p;
  }

  // events = on: H(z_b) = 0 for all inputs => grad H . (X + Y db) = 0.
  Row implicit_event_time_derivative(const Piece& p, double b) const {
    const V g = model_.grad_H(p.z);
    const double slope = g.dot(p.Y);  // dH/db along the piece: zero only at an exact tangency
    const double scale = g.template lpNorm<1>() * (p.Y.template lpNorm<Eigen::Infinity>() + 1e-300);
    if (!(std::abs(slope) > 1e-12 * scale))
      throw NumericalFailure("event step at t = " + format_number(t_) + ": event at offset " + format_number(b) +
                             " is tangential (dH/dt = " + format_number(slope) + "), its time has no derivative");
    return -(g.transpose() * p.X) / slope;
  }

  // events = linear: derivative of b = a - H/H' (from inside) or b = a - 2 H'/H'' (from the
  // surface), H' = g.F, H'' = g.(f_t + A F + B w'), F = f_j(t + a, z_a, w(a)); assumes grad H,
  // A and B constant within the region (model.hpp).
  Row linear_event_time_derivative(double a, const V& za, const Tangent& dza, const Row& da, int j,
                                   bool from_surface) const {
    const double ta = t_ + a;
    const W wa = w_at(a);
    const V g = model_.grad_H(za);
    const V F = model_.f(j, ta, za, wa), ft = model_.f_t(j, ta, za, wa);
    const M A = model_.A(j, ta, za, wa);
    const BM B = model_.B(j, ta, za, wa);
    // dw(a) = (1 - a/h) dw0 + (a/h) dw1 + w' da: DW rows
    Eigen::Matrix<double, DW, D + 2 * DW> dw = Eigen::Matrix<double, DW, D + 2 * DW>::Zero();
    dw.template middleCols<DW>(D) = (1 - a / h_) * Mat<DW>::Identity();
    dw.template rightCols<DW>() = (a / h_) * Mat<DW>::Identity();
    dw += wdot_ * da;
    const Tangent dF = A * dza + B * dw + ft * da;
    const double H1 = g.dot(F);
    const Row dH1 = g.transpose() * dF;
    if (!from_surface) {
      const double H0 = model_.H(za);
      const Row dH0 = g.transpose() * dza;
      return da - (dH0 * H1 - H0 * dH1) / (H1 * H1);
    }
    const V ftt = model_.f_tt(j, ta, za, wa);
    const double H2 = g.dot(ft + A * F + B * wdot_);
    Tangent dBwdot = Tangent::Zero();  // d(B w') = B (dw1 - dw0) / h
    dBwdot.template middleCols<DW>(D) = -B / h_;
    dBwdot.template rightCols<DW>() = B / h_;
    const Row dH2 = g.transpose() * (ftt * da + A * dF + dBwdot);
    return da - 2 * (dH1 * H2 - H1 * dH2) / (H2 * H2);
  }

  // The paper's estimates (events = linear), clamped to [a, limit].
  Exit linear_estimate(double a, const V& za, int j, bool from_surface, double limit) const {
    const double ta = t_ + a;
    const W wa = w_at(a);
    const V g = model_.grad_H(za);
    const V F = model_.f(j, ta, za, wa);
    const double H1 = g.dot(F);
    double b;
    if (!from_surface) {
      b = a - model_.H(za) / H1;
    } else {
      const double H2 =
          g.dot(model_.f_t(j, ta, za, wa) + model_.A(j, ta, za, wa) * F + model_.B(j, ta, za, wa) * wdot_);
      b = a - 2 * H1 / H2;
    }
    Exit e{true, b, from_surface, false};
    if (!(b > a && b < limit)) {  // outside the piece, or not finite
      e.b = std::isfinite(b) && b >= limit ? limit : a;
      e.clamped = true;
    }
    return e;
  }

  // The first time in (a, h] at which the piece in region j leaves it, if any (see the header).
  // zL: the piece's end if it ran to h.
  Exit find_exit(double a, const V& za, const V& zL, int j, bool on_surface) const {
    const int m = substeps(j);
    auto g = [&](double s) { return model_.H(piece_end(a, s, za, j, m)); };
    auto wrong = [j](double v) { return j == 1 ? v <= 0 : v > 0; };
    const double into = j == 1 ? 1 : -1;  // into * H > 0 deep inside region j
    const double ga = model_.H(za), gL = model_.H(zL);
    // A point in [a, limit) where H is on region j's side (strictly, unless it is a itself):
    // a when the piece does not start on the surface, else the deepest point (Brent).
    auto inside_point = [&](double limit, double& s, double& gs) {
      if (!on_surface && !wrong(ga)) {
        s = a, gs = ga;
        return true;
      }
      const ScalarSearchResult r = bounded_minimum([&](double x) { return -into * g(x); }, a, limit);
      s = r.x, gs = -into * r.g;
      return into * gs > 0;
    };
    double lo, glo;
    if (wrong(gL)) {                                                        // case 1: the piece ends on the other side
      if (!inside_point(h_, lo, glo)) return {true, a, on_surface, false};  // no resolvable time inside region j
      if (options_.events == EventMode::linear) return linear_estimate(a, za, j, on_surface, h_);
      return {true, root(g, lo, h_, glo, gL), on_surface, false};
    }
    if (!excursion_suspected(a, za, zL, ga, gL, j, on_surface)) return {};
    // case 2: the deepest point towards the other side
    const ScalarSearchResult r = bounded_minimum([&](double x) { return into * g(x); }, a, h_);
    const double gw = into * r.g;
    if (!(wrong(gw) && std::abs(gw) > threshold(za))) return {};
    if (!inside_point(r.x, lo, glo)) return {};
    if (options_.events == EventMode::linear) return linear_estimate(a, za, j, on_surface, r.x);
    return {true, root(g, lo, r.x, glo, gw), on_surface, false};
  }

  template <class G>
  double root(const G& g, double lo, double hi, double glo, double ghi) const {
    const ScalarSearchResult r = bracketed_root(g, lo, hi, glo, ghi);
    if (!std::isfinite(r.x))
      throw NumericalFailure("event step at t = " + format_number(t_) + ": event location failed in [" +
                             format_number(lo) + ", " + format_number(hi) + "]");
    return r.x;
  }

  // Does the cubic Hermite interpolant of H on [a, h] have an interior extremum within
  // `margin` of H = 0 (or beyond it)? Minima only unless the piece starts on the surface
  // (hermite_extremum_within, above the class).
  bool excursion_suspected(double a, const V& za, const V& zL, double ga, double gL, int j, bool on_surface) const {
    const double L = h_ - a;
    const double d0 = L * model_.grad_H(za).dot(model_.f(j, t_ + a, za, w_at(a)));
    const double d1 = L * model_.grad_H(zL).dot(model_.f(j, t_ + h_, zL, w1_));
    const double margin = std::abs(d1 - d0) + threshold(za);
    return hermite_extremum_within(ga, gL, d0, d1, margin, j == 1 ? 1 : -1, !on_surface);
  }

  const TrapezoidStepper<Model>& stepper_;
  const Model& model_;
  const StepOptions& options_;
  double t_, h_;
  W w0_, w1_, wdot_;
};

}  // namespace detail

template <class Model>
Vec<Model::d> event_step(const TrapezoidStepper<Model>& stepper, double t, double h, const Vec<Model::d>& u0,
                         const DelayedVec<Model>& w0, const DelayedVec<Model>& w1,
                         StepLinearisation<Model::d, delayed_rows<Model>>& linearisation, StepEvents* events) {
  return detail::EventStepSolver<Model>(stepper, t, h, w0, w1).run(u0, linearisation, events);
}

}  // namespace delayspec
