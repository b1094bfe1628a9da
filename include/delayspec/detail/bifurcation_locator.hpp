#pragma once
// Detection and location of the bifurcations between two consecutive points of a branch
// (continuation.hpp, "Detection" and "Location"). Part of continuation.hpp's implementation,
// included by it; not an interface.
//
// Location, on the segment's own curve s -> X(s) (the corrector from X_a + s t_a on the
// hyperplane <t_a, X - X_a - s t_a>_w = 0, s in [0, s_b]), of the zero of the type's test
// function g(s) (multiplier_test, or dp/ds at a turning point, or max H), in three stages:
//   1. bisection on the detection counts, which are exact, until g changes sign over the
//      sub-segment (a long segment may hold more than the one crossing: a pair colliding on the
//      real axis, the multiplier nearest +-1 not being the one that crosses);
//   2. the Illinois variant of regula falsi on the sign change, superlinear for a transversal
//      crossing, until the bracket is within the tolerance in p;
//   3. where the corrector fails on one side (near grazing the discrete problem is only
//      piecewise smooth and Newton may stall in contact), the one-sided secant through the last
//      two points on the other side, accepted when it moves the root by <= tolerance.
#include <algorithm>
#include <cmath>
#include <complex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "delayspec/continuation.hpp"
#include "delayspec/detail/branch_corrector.hpp"
#include "delayspec/detail/illinois.hpp"
#include "delayspec/errors.hpp"

namespace delayspec::continuation_detail {

// Multipliers outside the unit circle, by kind (the detection counts of continuation.hpp).
struct UnstableCounts {
  int real_plus = 0, real_minus = 0, complex = 0;
  int total() const { return real_plus + real_minus + complex; }
};
bool is_real(std::complex<double> mu);
UnstableCounts unstable_counts(const std::vector<std::complex<double>>& multipliers);
// The bifurcations (without grazing) whose counts change from a to b.
std::vector<BifurcationType> detected_changes(const UnstableCounts& a, const UnstableCounts& b);
// The test function of `type` (continuation.hpp), NaN when the point has no candidate multiplier;
// the critical multiplier in *critical.
double multiplier_test(BifurcationType type, const std::vector<std::complex<double>>& multipliers,
                       std::complex<double>* critical = nullptr);

// The test function a location finds the zero of: the critical multiplier's (multiplier_test),
// dp/ds at a turning point, max H (grazing), or the second hump's max H (the grazing of a second
// contact region on an orbit in contact: OrbitMeasures::second_max_H).
enum class LocatedBy { multiplier, turning_point, max_H, second_max_H };

// One location: a bifurcation of `type` on the segment from `base` (point a, s = 0) along its
// tangent, on the problem `branch` (branch_corrector.hpp). The corrector iterations, eigen-solves
// and their times are added to `cost`.
class BifurcationLocator {
 public:
  using State = BranchState;
  static constexpr int kMaxEvaluations = 60;  // corrected points per location, all stages

  static constexpr int kRefineEvaluations = 8;  // beyond `tolerance`, towards refine_tolerance

  // refine_tolerance: BranchRange's (0: none).
  BifurcationLocator(const BranchProblem& branch, ContinuationResult& cost, BifurcationType type, LocatedBy by,
                     const State& base, double tolerance, double refine_tolerance = 0)
      : branch_(branch),
        cost_(cost),
        type_(type),
        by_(by),
        base_(base),
        tolerance_(tolerance),
        target_(refine_tolerance > 0 ? std::min(refine_tolerance, tolerance) : tolerance) {}

  // The bifurcation between a (at base) and b (orbit xb, at arclength s_b along base's tangent);
  // `after`: the index of a on the branch.
  Bifurcation locate(const ContinuationPoint& a, const ContinuationPoint& b, const Eigen::VectorXd& xb, double s_b,
                     long after) {
    bif_.type = type_;
    bif_.after_point = after;
    if (by_ == LocatedBy::second_max_H) bif_.note = "a second contact region";
    neg_ = {0, test(a), a.parameter, a, base_.x};
    pos_ = {s_b, test(b), b.parameter, b, xb};
    s_b_ = s_b;
    slope_ = std::max({std::abs(b.parameter - a.parameter) / s_b, std::abs(a.tangent_p), std::abs(b.tangent_p)});
    if (type_ != BifurcationType::grazing) bisect_on_counts();
    if (neg_.g > 0) std::swap(neg_, pos_);
    illinois_ = {neg_.g, pos_.g};
    if (!(neg_.g < 0 && pos_.g > 0)) {
      bif_.note += std::string(bif_.note.empty() ? "" : "; ") +
                   "the test function does not change sign over the segment (" + format_number(neg_.g) + ", " +
                   format_number(pos_.g) + "): location by the nearer end";
    }
    while (neg_.g < 0 && pos_.g > 0 && bif_.evaluations < kMaxEvaluations)
      if (!illinois_step()) break;
    return finish();
  }

 private:
  // A corrected point of the segment with its test value; the negative / positive side of g.
  struct Sample {
    double s, g, p;
    ContinuationPoint point;
    Eigen::VectorXd x;  // the orbit (a switch at a period doubling starts from it)
  };

  // The test function (LocatedBy).
  double test(const ContinuationPoint& pt) const {
    switch (by_) {
      case LocatedBy::max_H: return pt.measures.max_H;
      case LocatedBy::second_max_H: return pt.measures.second_max_H;
      case LocatedBy::turning_point: return pt.tangent_p;  // dp/ds through 0
      case LocatedBy::multiplier: break;
    }
    return multiplier_test(type_, pt.multipliers);
  }

  // Whether the bifurcation is detected between x and y (the counts, or the sign of dp/ds).
  bool changes_here(const ContinuationPoint& x, const ContinuationPoint& y) const {
    if (by_ == LocatedBy::turning_point) return (x.tangent_p > 0) != (y.tangent_p > 0);
    const auto found = detected_changes(unstable_counts(x.multipliers), unstable_counts(y.multipliers));
    return std::find(found.begin(), found.end(), type_) != found.end();
  }

  // The corrected point at arclength s, evaluated; nullopt and the reason when the corrector or
  // the eigensolver fails. Counts one evaluation.
  std::optional<Sample> sample_at(double s, std::string& reason) {
    std::optional<State> st = branch_.point_along(base_, s, reason, cost_.newton_seconds);
    ++bif_.evaluations;
    if (!st) return std::nullopt;
    cost_.newton_iterations += st->iterations;
    ++cost_.krylov_solves;
    try {
      ContinuationPoint pt = branch_.evaluate(*st, cost_.krylov_seconds);
      const double g = test(pt);
      const double p = pt.parameter;
      return Sample{s, g, p, std::move(pt), std::move(st->x)};
    } catch (const NumericalFailure& e) {
      reason = e.what();
      return std::nullopt;
    }
  }

  // Stage 1, bisection on the detection counts: halves [neg, pos] (in the order of s) keeping
  // the half where the counts change, until g changes sign or the bracket is within the
  // tolerance. Stops at a failed point (stage 2 then starts from the bracket it has).
  void bisect_on_counts() {
    while (!(neg_.g * pos_.g < 0) && bif_.evaluations < kMaxEvaluations && std::abs(pos_.p - neg_.p) > tolerance_) {
      std::string reason;
      std::optional<Sample> mid = sample_at(0.5 * (neg_.s + pos_.s), reason);
      if (!mid) break;
      if (changes_here(neg_.point, mid->point)) pos_ = std::move(*mid);
      else neg_ = std::move(*mid);
    }
  }

  // Stage 3, the one-sided secant: the root of the line through (s, g) of prev_neg and neg.
  bool one_sided_secant(double& s_root) const {
    if (!prev_neg_ || neg_.g == prev_neg_->g) return false;
    s_root = neg_.s - neg_.g * (neg_.s - prev_neg_->s) / (neg_.g - prev_neg_->g);
    return std::isfinite(s_root);
  }

  // Stage 2, one Illinois step on g(neg) < 0 < g(pos) (illinois.hpp: the regula falsi point of
  // the working values, the side that did not move halved when the same side moved twice). After a failure on
  // the positive side the point is the one-sided secant root (bisection when the last step came
  // from that side). Returns false when done: the bracket is within the tolerance, the secant
  // puts the root within the tolerance of neg (located_), or g = 0 was hit.
  bool illinois_step() {
    const double width = std::abs(pos_.p - neg_.p), ds = std::abs(pos_.s - neg_.s);
    if (width <= target_) return false;
    // The discrete branch jumps between the two ends (near a grazing the discrete problem is not
    // continuous: the corrected points at s apart by 1e-15 of the segment had p apart by 1e-8 and
    // the test function jumped from -2.5e-8 to +1e-8, PWSDDE period-2 orbit at N = 200): the
    // bracket in s has shrunk a millionfold, the one in p has not. The jump is the accuracy.
    if (ds < 1e-6 * s_b_ && width > 1e3 * slope_ * ds) {
      bif_.note += std::string(bif_.note.empty() ? "" : "; ") + "the discrete branch jumps by " +
                   format_number(width) + " in p across the root: located to that";
      return false;
    }
    // Within the tolerance: narrowed on only while it works (BranchRange::refine_tolerance).
    if (width <= tolerance_ && (one_sided_ || refine_left_-- <= 0)) return false;
    double s_root;
    if (one_sided_secant(s_root)) {
      const double p_root = neg_.p + (s_root - neg_.s) * (neg_.p - prev_neg_->p) / (neg_.s - prev_neg_->s);
      const double move = std::abs(p_root - neg_.p);
      const bool close = move <= target_ || (move <= tolerance_ && (one_sided_ || refine_left_ <= 0));
      if (close && (s_root - neg_.s) * (pos_.s - neg_.s) >= 0) {
        located_ = p_root;
        return false;
      }
    }
    const double lo = std::min(neg_.s, pos_.s), hi = std::max(neg_.s, pos_.s), margin = 1e-3 * (hi - lo);
    double s = illinois_.root(neg_.s, pos_.s);  // regula falsi
    if (one_sided_) s = one_sided_secant(s_root) && illinois_.last != 1 ? s_root : 0.5 * (lo + hi);
    s = std::clamp(s, lo + margin, hi - margin);
    std::string reason;
    std::optional<Sample> sample = sample_at(s, reason);
    if (!sample || !std::isfinite(sample->g)) {
      // Taken as the positive side (for grazing the side in contact, where the discrete problem
      // is least smooth); from now on the root comes from the negative side. The failed point has
      // no parameter of its own: p along the segment's chord stands in for it, so that the
      // bracket in p shrinks with the bisection (before, it kept the last good point's p and a
      // location near a grazing spent all its evaluations on a bracket that could not narrow).
      one_sided_ = true;
      pos_.p = neg_.p + (s - neg_.s) * (pos_.p - neg_.p) / (pos_.s - neg_.s);
      pos_.s = s;
      illinois_.last = 1;
      // (one note per location: the last failure's; a second contact region's prefix kept)
      bif_.note = std::string(by_ == LocatedBy::second_max_H ? "a second contact region; " : "") +
                  "located from one side: " + (sample ? std::string("no candidate multiplier") : reason) +
                  " at s = " + format_number(s);
      return true;
    }
    const double g = sample->g;
    if (g == 0) {
      neg_ = std::move(*sample);
      pos_ = neg_;
      return false;
    }
    if (illinois_.replace(g) < 0) {  // (the end a is the negative side)
      prev_neg_ = std::move(neg_);
      neg_ = std::move(*sample);
    } else {
      pos_ = std::move(*sample);
    }
    return true;
  }

  // The bifurcation at the root found (the secant's) or at the end of the bracket nearer the
  // root (the negative end after a one-sided location), with its multipliers, measures, orbit
  // and the critical multiplier's angle; notes for a wide bracket and a nonsmooth fold.
  Bifurcation finish() {
    const Sample& nearer = std::abs(neg_.g) <= std::abs(pos_.g) || one_sided_ ? neg_ : pos_;
    const ContinuationPoint& best = nearer.point;
    bif_.bracket = std::isfinite(located_) ? std::abs(located_ - neg_.p) : std::abs(pos_.p - neg_.p);
    if (bif_.bracket > tolerance_)
      bif_.note += std::string(bif_.note.empty() ? "" : "; ") + "bracket " + format_number(bif_.bracket) +
                   " wider than the tolerance after " + std::to_string(bif_.evaluations) + " evaluations";
    bif_.parameter = std::isfinite(located_) ? located_ : best.parameter;
    bif_.multipliers = best.multipliers;
    bif_.measures = best.measures;
    bif_.orbit = nearer.x;
    bif_.period = best.period;
    std::complex<double> critical;
    if (type_ == BifurcationType::grazing) {
      bif_.angle = NAN;
    } else if (std::isfinite(multiplier_test(type_, best.multipliers, &critical))) {
      bif_.angle = std::abs(std::arg(critical));
      if (by_ == LocatedBy::turning_point && std::abs(critical - 1.0) > 1e-3)
        bif_.note += std::string(bif_.note.empty() ? "" : "; ") + "a turning point with no multiplier at +1 (nearest " +
                     format_number(critical.real()) + "): a nonsmooth fold";
    }
    return std::move(bif_);
  }

  const BranchProblem& branch_;
  ContinuationResult& cost_;
  const BifurcationType type_;
  const LocatedBy by_;
  const State& base_;
  const double tolerance_;
  const double target_;  // refine_tolerance when given, else tolerance
  double s_b_ = 0, slope_ = 0;  // the segment's length and a scale of |dp/ds| along it

  Bifurcation bif_;
  int refine_left_ = kRefineEvaluations;
  Sample neg_, pos_;                // the samples on the negative and the positive side of g
  std::optional<Sample> prev_neg_;  // the negative sample before neg_ (the one-sided secant)
  detail::IllinoisValues illinois_; // a: neg_.g, b: pos_.g, possibly halved; the side moved last
  bool one_sided_ = false;          // a point failed on the positive side: the root from the negative side
  double located_ = NAN;            // the root from the one-sided secant
};

}  // namespace delayspec::continuation_detail
