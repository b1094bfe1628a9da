#pragma once
// The branch tracer of continue_orbit, continue_period_doubled and continue_from_hopf: predictor,
// corrector, step control, the ends of the range, detection of bifurcations between consecutive
// points (continuation.hpp states the method). Part of continuation.hpp's implementation; not an
// interface. Not a template: compiled once, in src/engine/continuation_branch.cpp, over the
// abstract BranchProblem (branch_corrector.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "delayspec/continuation.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/detail/bifurcation_locator.hpp"
#include "delayspec/detail/branch_corrector.hpp"

namespace delayspec::continuation_detail {

// One branch from its first point to an end (continuation.hpp, "End of the branch"), of the
// problem `branch` (PeriodicBranch: a forced orbit; AutonomousBranch: an orbit of unknown period).
class BranchTracer {
 public:
  using State = BranchState;

  // start_tangent: see trace_branch.
  BranchTracer(const BranchProblem& branch, const ContinuationOptions& options, const Eigen::VectorXd* start_tangent,
               double start_p)
      : o_(checked_options(options)),
        direction_(o_.to > o_.from ? 1 : -1),
        start_tangent_(start_tangent),
        start_p_(start_p),
        branch_(branch) {}

  // The branch from `guess`: its first point, then predictor-corrector steps until an end.
  ContinuationResult trace(const Eigen::VectorXd& guess) {
    const long n = branch_.unknowns();
    if (guess.size() != n)
      throw BadInput("continuation: the start sequence has " + std::to_string(guess.size()) + " entries, expected " +
                     std::to_string(n));
    zero_row_ = Eigen::VectorXd::Zero(n);
    start(guess);
    ds_ = o_.step;
    result_.end = BranchEnd::max_points;
    while (static_cast<long>(result_.points.size()) < o_.max_points)
      if (!advance()) break;
    return std::move(result_);
  }

 private:
  // The first point: Newton at p = from with the tangent towards `to`; or, with a start tangent,
  // the given point (guess, start_p) and that tangent normalised (no Newton: the point may be
  // singular). NumericalFailure when Newton fails.
  void start(const Eigen::VectorXd& guess) {
    const long n = branch_.unknowns();
    std::string why;
    if (start_tangent_) {
      if (start_tangent_->size() != n + 1)
        throw BadInput("continuation: the start tangent has " + std::to_string(start_tangent_->size()) + " entries");
      const Eigen::VectorXd& t = *start_tangent_;
      State given;
      given.x = guess;
      given.p = start_p_;
      const double norm = std::sqrt(branch_.dot(t.head(n), t[n], t.head(n), t[n]));
      given.tx = t.head(n) / norm;
      given.tp = t[n] / norm;
      current_ = std::move(given);
    } else {
      current_ =
          branch_.correct(guess, o_.from, zero_row_, 1.0, o_.from, o_.start_iterations, why, result_.newton_seconds);
    }
    if (!current_)
      throw NumericalFailure("continuation start: Newton on the periodic orbit at parameter " + format_number(o_.from) +
                             " failed: " + why);
    if (!start_tangent_ && current_->tp * direction_ < 0) {
      current_->tx = -current_->tx;
      current_->tp = -current_->tp;
    }
    result_.newton_iterations += current_->iterations;
    add_point(branch_.evaluate(*current_, result_.krylov_seconds));
  }

  void add_point(ContinuationPoint point) {
    ++result_.krylov_solves;
    result_.points.push_back(std::move(point));
    if (o_.on_point) o_.on_point(result_.points.back());
  }

  // One step of the branch: the next point at arclength ds from the current one (the step
  // halved until the corrector succeeds), or the point at the end of the range, with the
  // bifurcations before it located and the next step's length. False when the branch ends here.
  bool advance() {
    // A predictor past `to` is shortened to land on it (the model may not exist beyond).
    if ((current_->p + ds_ * current_->tp - o_.to) * direction_ > 0 && std::abs(current_->tp) > 0.1)
      ds_ = std::max((o_.to - current_->p) / current_->tp, o_.step_min);
    std::string reason;
    std::optional<State> next = accepted_step(reason);
    if (!next) return halve_step(reason);
    result_.newton_iterations += next->iterations;
    double s_b = ds_;
    const bool last = end_of_range(next, s_b);
    ContinuationPoint point;
    try {
      point = branch_.evaluate(*next, result_.krylov_seconds);
    } catch (const NumericalFailure& e) {
      result_.end = BranchEnd::failure;
      result_.failure = "multipliers at parameter " + format_number(next->p) + " (after point " +
                        std::to_string(result_.points.size() - 1) + "): " + e.what();
      return false;
    }
    point.step = ds_;
    if (o_.locate && !(start_tangent_ && result_.points.size() == 1)) {
      const ContinuationPoint a = result_.points.back();
      locate_between(a, point, next->x, s_b);
    }
    const int iterations = next->iterations;
    previous_state_ = std::move(current_);
    current_ = std::move(next);
    add_point(std::move(point));
    if (last) return false;
    // Step control by the corrector's iterations (continuation.hpp).
    if (iterations <= 3) ds_ = std::min(1.5 * ds_, o_.step_max);
    else if (iterations >= 6) ds_ = std::max(0.7 * ds_, o_.step_min);
    return true;
  }

  // The corrected point at arclength ds_ along the current tangent, its tangent oriented along the
  // branch (<t_next, t_current>_w > 0); nullopt and the reason when the corrector fails, when
  // the tangent turns by more than ~37 degrees (cos < 0.8: a jump to another branch), or when
  // consecutive secants make an angle above 90 degrees (the branch would retrace itself).
  std::optional<State> accepted_step(std::string& reason) {
    std::optional<State> next = branch_.point_along(*current_, ds_, reason, result_.newton_seconds);
    if (next && branch_.dot(next->tx, next->tp, current_->tx, current_->tp) < 0) {
      next->tx = -next->tx;  // keep the orientation
      next->tp = -next->tp;
    }
    if (next && branch_.dot(next->tx, next->tp, current_->tx, current_->tp) < 0.8) {
      reason =
          "the tangent turned by " +
          format_number(std::acos(std::clamp(branch_.dot(next->tx, next->tp, current_->tx, current_->tp), -1.0, 1.0))) +
          " rad";
      next.reset();
    }
    if (next && previous_state_) {
      // At a smooth fold the state keeps moving and the secants turn by O(ds). Seen at a corner of
      // a piecewise-smooth branch (an impact grazing with |mu| -> 1), where the corrector beyond
      // the corner lands on the same branch behind it.
      const Eigen::VectorXd d1x = current_->x - previous_state_->x, d2x = next->x - current_->x;
      const double d1p = current_->p - previous_state_->p, d2p = next->p - current_->p;
      const double cosine = branch_.dot(d1x, d1p, d2x, d2p) /
                            std::sqrt(branch_.dot(d1x, d1p, d1x, d1p) * branch_.dot(d2x, d2p, d2x, d2p));
      if (cosine < 0) {
        reason = "the branch turns back on itself (consecutive secants at " +
                 format_number(std::acos(std::clamp(cosine, -1.0, 1.0))) + " rad: a corner, not a smooth fold)";
        next.reset();
      }
    }
    return next;
  }

  // A rejected step: retried with half the step; below step_min the branch ends with `failure`
  // (false).
  bool halve_step(const std::string& reason) {
    ds_ *= 0.5;
    if (!(ds_ < o_.step_min)) return true;
    const ContinuationPoint& last = result_.points.back();
    result_.end = BranchEnd::failure;
    result_.failure = "step below continue_step_min = " + format_number(o_.step_min) + " after point " +
                      std::to_string(result_.points.size() - 1) + " at parameter " + format_number(last.parameter) +
                      " (" + reason + ")";
    return false;
  }

  // A point past `to`, or back past `from`, is replaced by the point at exactly that end (Newton
  // with p fixed; kept as it is when that fails), s_b its arclength from the current point along
  // the current tangent. True (and the end recorded) when the point is past an end.
  bool end_of_range(std::optional<State>& next, double& s_b) {
    const double past_to = (next->p - o_.to) * direction_, before_from = (o_.from - next->p) * direction_;
    if (!(past_to >= 0 || before_from > 0)) return false;
    const double end_p = past_to >= 0 ? o_.to : o_.from;
    std::string reason;
    std::optional<State> end = branch_.correct(next->x, next->p, zero_row_, 1.0, end_p, o_.newton.max_iterations,
                                               reason, result_.newton_seconds);
    if (end) {
      if (branch_.dot(end->tx, end->tp, next->tx, next->tp) < 0) end->tx = -end->tx, end->tp = -end->tp;
      s_b = branch_.dot(current_->tx, current_->tp, end->x - current_->x, end->p - current_->p);
      next = std::move(end);
    }
    result_.end = past_to >= 0 ? BranchEnd::to : BranchEnd::from;
    return true;
  }

  // Detection between the last point a and the new point b (orbit xb, arclength s_b along the
  // current tangent): the changes of the counts; a turning point of the parameter is a fold,
  // located where dp/ds = 0 (for the discrete problem exactly where F_x is singular: a
  // multiplier +1, or at a corner of a piecewise-smooth branch none); a multiplier through +1
  // without one (a branch point) by the multiplier; grazing by the sign of max H, and on an orbit
  // in contact at both ends the grazing of a second contact region by the sign of the second
  // hump's max H (OrbitMeasures::second_max_H). Each located.
  void locate_between(const ContinuationPoint& a, const ContinuationPoint& b, const Eigen::VectorXd& xb, double s_b) {
    std::vector<std::pair<BifurcationType, LocatedBy>> found;
    for (BifurcationType type : detected_changes(unstable_counts(a.multipliers), unstable_counts(b.multipliers)))
      found.push_back({type, LocatedBy::multiplier});
    const bool turning = (a.tangent_p > 0) != (b.tangent_p > 0);
    if (turning) {  // the fold by dp/ds, whether or not a multiplier went through +1
      auto fold =
          std::find_if(found.begin(), found.end(), [](const auto& f) { return f.first == BifurcationType::fold; });
      if (fold == found.end()) found.push_back({BifurcationType::fold, LocatedBy::turning_point});
      else fold->second = LocatedBy::turning_point;
    }
    if (branch_.has_switching()) {
      if ((a.measures.max_H > 0) != (b.measures.max_H > 0))
        found.push_back({BifurcationType::grazing, LocatedBy::max_H});
      else if (a.measures.max_H > 0 && (a.measures.second_max_H > 0) != (b.measures.second_max_H > 0))
        found.push_back({BifurcationType::grazing, LocatedBy::second_max_H});
    }
    const long after = static_cast<long>(result_.points.size()) - 1;
    for (const auto& [type, by] : found) {
      const auto locate_start = std::chrono::steady_clock::now();
      BifurcationLocator locator(branch_, result_, type, by, *current_, o_.tolerance, o_.refine_tolerance);
      result_.bifurcations.push_back(locator.locate(a, b, xb, s_b, after));
      result_.locate_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - locate_start).count();
    }
  }

  const ContinuationOptions o_;
  const double direction_;
  const Eigen::VectorXd* const start_tangent_;
  const double start_p_;
  const BranchProblem& branch_;

  ContinuationResult result_;
  Eigen::VectorXd zero_row_;             // the row of the constraint p = const
  std::optional<State> current_;         // the last point
  std::optional<State> previous_state_;  // the point before current_
  double ds_ = 0;                        // the next arclength step
};

}  // namespace delayspec::continuation_detail
