// The non-template parts of continuation.hpp and its detail headers: the checked options,
// detection counts, test functions, the Hermite maximum, and the extrapolation of bifurcation
// points across N.
#include "delayspec/continuation.hpp"
#include "delayspec/detail/bifurcation_locator.hpp"
#include "delayspec/detail/cubic_hermite.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace delayspec {

std::string to_string(BifurcationType type) {
  switch (type) {
    case BifurcationType::fold: return "fold";
    case BifurcationType::period_doubling: return "period-doubling";
    case BifurcationType::neimark_sacker: return "neimark-sacker";
    case BifurcationType::grazing: return "grazing";
  }
  return "?";
}

BifurcationType crossing_type(std::complex<double> mu) {
  if (!continuation_detail::is_real(mu)) return BifurcationType::neimark_sacker;
  return mu.real() > 0 ? BifurcationType::fold : BifurcationType::period_doubling;
}

std::string to_string(BranchEnd end) {
  switch (end) {
    case BranchEnd::to: return "to";
    case BranchEnd::from: return "from";
    case BranchEnd::max_points: return "max_points";
    case BranchEnd::failure: return "failure";
  }
  return "?";
}

std::string to_string(ContinuationSolver solver) {
  switch (solver) {
    case ContinuationSolver::automatic: return "auto";
    case ContinuationSolver::krylov: return "krylov";
    case ContinuationSolver::lu: return "lu";
  }
  return "?";
}

BranchRange checked_range(const BranchRange& range) {
  BranchRange o = range;
  // Named by the fields: the scene layer checks its keys before (continue_settings.cpp).
  require_finite("BranchRange::from", o.from);
  require_finite("BranchRange::to", o.to);
  if (o.from == o.to) throw BadInput("`BranchRange::from = to = " + format_number(o.from) + "`: an empty range");
  const double width = std::abs(o.to - o.from);
  if (o.step == 0) o.step = width / 50;
  if (o.step_min == 0) o.step_min = 1e-6 * width;
  if (o.step_max == 0) o.step_max = width / 10;
  if (o.tolerance == 0) o.tolerance = 1e-10 * width;
  require_positive("BranchRange::step", o.step);
  require_positive("BranchRange::step_min", o.step_min);
  require_positive("BranchRange::step_max", o.step_max);
  require_positive("BranchRange::tolerance", o.tolerance);
  if (!(o.refine_tolerance >= 0) || !std::isfinite(o.refine_tolerance))
    throw BadInput("`BranchRange::refine_tolerance = " + format_number(o.refine_tolerance) + "`: must be >= 0");
  if (o.step_min > o.step_max)
    throw BadInput("`BranchRange::step_min = " + format_number(o.step_min) + "` exceeds `step_max = " +
                   format_number(o.step_max) + "`" + (range.step_max == 0 ? " (its default, |to - from| / 10)" : ""));
  o.step = std::clamp(o.step, o.step_min, o.step_max);
  if (o.max_points < 2)
    throw BadInput("`BranchRange::max_points = " + std::to_string(o.max_points) + "`: must be >= 2");
  return o;
}

namespace continuation_detail {

ContinuationOptions checked_options(const ContinuationOptions& options) {
  ContinuationOptions o = options;
  static_cast<BranchRange&>(o) = checked_range(options);
  if (!(o.forcing_max > 0 && o.forcing_max < 1))
    throw BadInput("`ContinuationOptions::forcing_max = " + format_number(o.forcing_max) + "`: must be in (0, 1)");
  if (o.gmres_restart < 1 || o.gmres_max_iterations < 1)
    throw BadInput("`ContinuationOptions::gmres_restart = " + std::to_string(o.gmres_restart) +
                   "`, `gmres_max_iterations = " + std::to_string(o.gmres_max_iterations) + "`: must be >= 1");
  return o;
}

bool is_real(std::complex<double> mu) { return std::abs(mu.imag()) <= 1e-10 * std::abs(mu); }

UnstableCounts unstable_counts(const std::vector<std::complex<double>>& multipliers) {
  // A multiplier within 1e-12 of the circle is not counted outside: its side is rounding. Where the
  // step cannot resolve the model (x' = a x + 0.5 x(t - 1) at a = 1e20: h a beyond 4 / eps, the
  // trapezoid's factor (1 + h a / 2) / (1 - h a / 2) rounds to -1) every multiplier is 1 to a few
  // ulps, 1 + 2e-16 at one point and 1 - 1.3e-14 at the next, and each flip was a "fold" printed
  // at exit 0 (issue 61 item 9). 1e-12: above the rounding of a product of 10^4 step maps
  // (K eps ~ 2e-12 at most, measured 1.3e-14 here), far below any crossing a step resolves.
  constexpr double kOnCircle = 1e-12;
  UnstableCounts c;
  for (const auto& mu : multipliers) {
    if (!(std::abs(mu) > 1 + kOnCircle)) continue;
    if (!is_real(mu)) ++c.complex;
    else if (mu.real() > 0) ++c.real_plus;
    else ++c.real_minus;
  }
  return c;
}

std::vector<BifurcationType> detected_changes(const UnstableCounts& a, const UnstableCounts& b) {
  std::vector<BifurcationType> found;
  const bool fold = (a.real_plus - b.real_plus) % 2 != 0;
  const bool period_doubling = (a.real_minus - b.real_minus) % 2 != 0;
  if (fold) found.push_back(BifurcationType::fold);
  if (period_doubling) found.push_back(BifurcationType::period_doubling);
  // Non-real multipliers leaving / entering the circle, unless the change is a real pair turning
  // complex (or back) outside it: then the total of unstable multipliers is what the real
  // crossings alone explain.
  const int real_change = (b.real_plus - a.real_plus) * fold + (b.real_minus - a.real_minus) * period_doubling;
  if (a.complex != b.complex && b.total() - a.total() != real_change) found.push_back(BifurcationType::neimark_sacker);
  return found;
}

double multiplier_test(BifurcationType type, const std::vector<std::complex<double>>& multipliers,
                       std::complex<double>* critical) {
  double best_distance = INFINITY, value = NAN;
  for (const auto& mu : multipliers) {
    double distance = INFINITY, g = NAN;
    if (type == BifurcationType::fold && is_real(mu) && mu.real() > 0) {
      distance = std::abs(mu.real() - 1);
      g = mu.real() - 1;
    } else if (type == BifurcationType::period_doubling && is_real(mu) && mu.real() < 0) {
      distance = std::abs(mu.real() + 1);
      g = -mu.real() - 1;
    } else if (type == BifurcationType::neimark_sacker && !is_real(mu)) {
      distance = std::abs(std::abs(mu) - 1);
      g = std::abs(mu) - 1;
    }
    if (distance < best_distance) {
      best_distance = distance;
      value = g;
      if (critical) *critical = mu;
    }
  }
  return value;
}

}  // namespace continuation_detail

std::vector<BifurcationEstimate> extrapolate_bifurcations(const std::vector<int>& Ns,
                                                          const std::vector<std::vector<Bifurcation>>& by_N,
                                                          double location_accuracy,
                                                          const RichardsonOptions& richardson) {
  if (Ns.size() != by_N.size())
    throw BadInput("extrapolate_bifurcations: " + std::to_string(Ns.size()) + " levels but " +
                   std::to_string(by_N.size()) + " lists of bifurcations");
  if (Ns.empty()) return {};
  for (size_t i = 1; i < Ns.size(); ++i)
    if (Ns[i] <= Ns[i - 1])
      throw BadInput("extrapolate_bifurcations: the Ns must be increasing (" + std::to_string(Ns[i - 1]) + ", " +
                     std::to_string(Ns[i]) + ")");
  std::vector<BifurcationEstimate> estimates;
  const size_t finest = Ns.size() - 1;
  std::vector<std::set<size_t>> used(Ns.size());
  for (const Bifurcation& b : by_N[finest]) {
    BifurcationEstimate e;
    e.type = b.type;
    e.parameter = b.parameter;
    e.angle = b.angle;
    std::vector<double> h, values, accuracy;
    for (size_t level = 0; level < Ns.size(); ++level) {
      const Bifurcation* match = nullptr;
      size_t match_index = 0;
      if (level == finest) {
        match = &b;
      } else {
        for (size_t j = 0; j < by_N[level].size(); ++j) {
          const Bifurcation& c = by_N[level][j];
          if (c.type != b.type || used[level].count(j)) continue;
          if (!match || std::abs(c.parameter - b.parameter) < std::abs(match->parameter - b.parameter)) {
            match = &c;
            match_index = j;
          }
        }
        if (match) used[level].insert(match_index);
      }
      if (!match) continue;
      e.Ns.push_back(Ns[level]);
      e.parameters.push_back(match->parameter);
      e.angles.push_back(match->angle);
      h.push_back(1.0 / Ns[level]);
      values.push_back(match->parameter);
      // A location is known to its final bracket when that stayed wider than the tolerance.
      accuracy.push_back(std::max(location_accuracy, match->bracket));
    }
    if (values.size() < Ns.size())
      e.note = "found at " + std::to_string(values.size()) + " of " + std::to_string(Ns.size()) + " levels; ";
    if (values.size() >= 3) {
      const size_t L = values.size();
      const double d1 = std::abs(values[L - 2] - values[L - 3]), d2 = std::abs(values[L - 1] - values[L - 2]);
      const double r = std::sqrt(h[L - 3] / h[L - 1]);
      if (d1 > 0 && d2 > 0) e.observed_order = std::log(d1 / d2) / std::log(r);
    }
    if (values.size() >= 2) {
      std::vector<std::complex<double>> x(values.begin(), values.end());
      const Extrapolation ex = richardson_extrapolate(h, x, richardson, accuracy);
      e.extrapolated = ex.value.real();
      e.error_estimate = ex.error_estimate;
      e.note += ex.note;
      // The Neimark-Sacker angle converges as the location does (the same expansion in h).
      if (e.type == BifurcationType::neimark_sacker) {
        const std::vector<std::complex<double>> angles(e.angles.begin(), e.angles.end());
        const Extrapolation ea = richardson_extrapolate(h, angles, richardson);
        e.angle_extrapolated = ea.value.real();
        e.angle_error_estimate = ea.error_estimate;
      }
    } else {
      e.extrapolated = b.parameter;
      e.note += "one level: no error estimate";
    }
    estimates.push_back(std::move(e));
  }
  return estimates;
}

}  // namespace delayspec
