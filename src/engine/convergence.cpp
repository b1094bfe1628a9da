#include "delayspec/convergence.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "delayspec/multipliers.hpp"
#include "delayspec/errors.hpp"

namespace delayspec {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kMinPrecision = 1e-16;  // no reference is better than double rounding
// Relative size below which a successive difference is treated as round-off (eigen-solver noise
// dominates there, the discretisation error is no longer visible).
constexpr double kNoiseFloor = 1e-13;

// Least-squares slope of y against x (NaN with fewer than two points or no spread in x).
double slope(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = x.size();
  if (n < 2) return kNaN;
  double mx = 0, my = 0;
  for (size_t i = 0; i < n; ++i) mx += x[i] / n, my += y[i] / n;
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < n; ++i) sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
  return sxx > 0 ? sxy / sxx : kNaN;
}

double relative_error(std::complex<double> value, std::complex<double> reference) {
  const double scale = std::abs(reference);
  return std::abs(value - reference) / (scale > 0 ? scale : 1.0);
}

void validate(const ConvergenceOptions& o) {
  if (o.Ns.empty()) throw BadInput("convergence study: `Ns` is empty: give at least one N");
  for (size_t i = 0; i < o.Ns.size(); ++i) {
    if (o.Ns[i] < 1) throw BadInput("convergence study: `N = " + std::to_string(o.Ns[i]) + "`: must be >= 1");
    if (i > 0 && o.Ns[i] <= o.Ns[i - 1])
      throw BadInput("convergence study: `Ns`: must be strictly increasing (" + std::to_string(o.Ns[i - 1]) + " then " +
                     std::to_string(o.Ns[i]) + ")");
  }
  if (o.nev < 1) throw BadInput("convergence study: `nev = " + std::to_string(o.nev) + "`: must be >= 1");
  if (o.extra < 0) throw BadInput("convergence study: `extra = " + std::to_string(o.extra) + "`: must be >= 0");
  if (!(o.settled_spread > 0))
    throw BadInput("convergence study: `settled_spread = " + format_number(o.settled_spread) + "`: must be > 0");
  if (o.reference == ReferenceKind::exact && static_cast<int>(o.exact.size()) < o.nev)
    throw BadInput("convergence study: `reference = exact` needs " + std::to_string(o.nev) +
                   " exact multipliers, this model provides " + std::to_string(o.exact.size()) +
                   " (use reference = extrapolated or finest)");
  if ((o.reference == ReferenceKind::extrapolated || o.reference == ReferenceKind::finest) && o.Ns.size() < 2)
    throw BadInput("convergence study: `reference = " + to_string(o.reference) +
                   "` needs at least two N, got `Ns` of " + std::to_string(o.Ns.size()));
  if (o.reference == ReferenceKind::automatic && o.exact.empty() && o.Ns.size() < 2)
    throw BadInput("convergence study: no exact multipliers and one N only: give at least two N");
  if (!(o.target >= 0 && o.target < 1))
    throw BadInput("`converge_target = " + format_number(o.target) +
                   "`: must be a relative error in (0, 1) (0: no target)");
  if (o.target > 0 && o.max_N < o.Ns.back())
    throw BadInput("`converge_max_N = " + std::to_string(o.max_N) + "`: below the largest N of `Ns`, " +
                   std::to_string(o.Ns.back()));
  if (!(o.max_seconds > 0) || !std::isfinite(o.max_seconds))
    throw BadInput("`converge_max_seconds = " + format_number(o.max_seconds) + "`: must be > 0 and finite");
}

// Why a study cannot go on: every level that failed, with its reason.
std::string failures_text(const std::vector<int>& Ns, const std::vector<LevelResult>& levels) {
  std::string text;
  for (size_t i = 0; i < levels.size(); ++i)
    if (!levels[i].failure.empty()) text += "\n  N = " + std::to_string(Ns[i]) + ": " + levels[i].failure;
  return text;
}

// Settledness of a list of pair orders (design 1.5: pre-asymptotic behaviour must be said).
void judge(OrderReport& r, const std::vector<double>& log_x, const std::vector<double>& log_y, double spread_limit) {
  const size_t n = r.pair_orders.size();
  if (n == 0) {
    r.note = r.basis == "error" ? "no order: fewer than two levels with an error above the reference precision"
                                : "no order: needs three levels whose successive differences are above round-off";
    return;
  }
  if (n == 1) {
    r.observed = r.pair_orders[0];
    r.note = "one pair of levels only: whether the order has settled cannot be checked";
    return;
  }
  const size_t m = std::min<size_t>(3, n);
  const auto first = r.pair_orders.end() - static_cast<long>(m);
  const double lo = *std::min_element(first, r.pair_orders.end());
  const double hi = *std::max_element(first, r.pair_orders.end());
  r.settled = hi - lo <= spread_limit;
  if (r.settled) {
    // Slope over the points behind the last m pair orders (m + 1 points).
    const size_t k = std::min(log_x.size(), m + 1);
    std::vector<double> xs(log_x.end() - static_cast<long>(k), log_x.end());
    std::vector<double> ys(log_y.end() - static_cast<long>(k), log_y.end());
    r.observed = -slope(xs, ys);
  } else {
    char buf[200];
    std::snprintf(
        buf, sizeof buf,
        "orders not settled: the last %zu pair orders range over [%.3g, %.3g] (spread %.2g > %.2g): pre-asymptotic, refine N",
        m, lo, hi, hi - lo, spread_limit);
    r.note = buf;
  }
}

// Order of one track: from errors (exact reference) or from successive differences.
OrderReport track_order(const std::vector<int>& Ns, const std::vector<std::complex<double>>& values,
                        const std::vector<double>& errors, bool exact_reference, double precision,
                        double spread_limit) {
  OrderReport r;
  std::vector<double> log_x, log_y;
  const size_t L = Ns.size();
  if (exact_reference) {
    r.basis = "error";
    const double floor = std::max(10 * precision, kNoiseFloor);
    std::vector<bool> usable(L);
    for (size_t i = 0; i < L; ++i) usable[i] = errors[i] > floor && std::isfinite(errors[i]);
    for (size_t i = 0; i < L; ++i)
      if (usable[i]) log_x.push_back(std::log(Ns[i])), log_y.push_back(std::log(errors[i]));
    for (size_t i = 0; i + 1 < L; ++i)
      if (usable[i] && usable[i + 1]) {
        r.pair_orders.push_back(std::log(errors[i] / errors[i + 1]) / std::log(double(Ns[i + 1]) / Ns[i]));
        r.pair_N.push_back(Ns[i + 1]);
      }
  } else {
    r.basis = "difference";
    std::vector<double> d(L > 0 ? L - 1 : 0);
    std::vector<bool> usable(d.size());
    for (size_t i = 0; i + 1 < L; ++i) {
      d[i] = std::abs(values[i + 1] - values[i]);
      const double scale = std::max(std::abs(values[i + 1]), 1e-300);
      usable[i] = d[i] / scale > kNoiseFloor;
      if (usable[i]) log_x.push_back(std::log(Ns[i])), log_y.push_back(std::log(d[i]));
    }
    for (size_t i = 0; i + 1 < d.size(); ++i)
      if (usable[i] && usable[i + 1]) {
        // h = 1 / N: any ratios (order_of_differences, richardson.hpp)
        r.pair_orders.push_back(order_of_differences(1.0 / Ns[i], 1.0 / Ns[i + 1], 1.0 / Ns[i + 2], d[i], d[i + 1]));
        r.pair_N.push_back(Ns[i + 2]);
      }
  }
  r.least_squares = -slope(log_x, log_y);
  judge(r, log_x, log_y, spread_limit);
  return r;
}

// Hungarian algorithm (potentials, O(n^2 m)) for an n x m cost matrix, n <= m.
std::vector<int> hungarian(const std::vector<std::vector<double>>& cost, int n, int m) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0), v(m + 1, 0);
  std::vector<int> p(m + 1, 0), way(m + 1, 0);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(m + 1, inf);
    std::vector<char> used(m + 1, false);
    do {
      used[j0] = true;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double cur = cost[i0 - 1][j - 1] - u[i0] - v[j];  // reduced cost
        if (cur < minv[j]) minv[j] = cur, way[j] = j0;
        if (minv[j] < delta) delta = minv[j], j1 = j;
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) u[p[j]] += delta, v[j] -= delta;
        else minv[j] -= delta;
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {  // augment along the alternating path
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> assignment(n, -1);
  for (int j = 1; j <= m; ++j)
    if (p[j] != 0) assignment[p[j] - 1] = j - 1;
  return assignment;
}

}  // namespace

std::string to_string(ReferenceKind kind) {
  switch (kind) {
    case ReferenceKind::exact: return "exact";
    case ReferenceKind::extrapolated: return "extrapolated";
    case ReferenceKind::finest: return "finest";
    case ReferenceKind::automatic: return "auto";
  }
  return "?";
}

std::vector<int> match_by_proximity(const Multipliers& targets, const Multipliers& candidates) {
  if (candidates.size() < targets.size())
    throw BadInput("match_by_proximity: " + std::to_string(targets.size()) + " targets but only " +
                   std::to_string(candidates.size()) + " candidates");
  auto finite = [](std::complex<double> z) { return std::isfinite(z.real()) && std::isfinite(z.imag()); };
  for (auto z : targets)
    if (!finite(z)) throw BadInput("match_by_proximity: a target is not finite");
  for (auto z : candidates)
    if (!finite(z)) throw BadInput("match_by_proximity: a candidate is not finite");
  const int n = static_cast<int>(targets.size()), m = static_cast<int>(candidates.size());
  if (n == 0) return {};
  std::vector<std::vector<double>> cost(n, std::vector<double>(m));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) cost[i][j] = std::abs(targets[i] - candidates[j]);
  return hungarian(cost, n, m);
}

double correct_digits(double relative_error, double reference_precision) {
  const double cap = -std::log10(std::max(reference_precision, kMinPrecision)) + 0.0;  // + 0.0: no "-0" at precision 1
  if (!(relative_error > 0)) return cap;
  return std::min(cap, -std::log10(relative_error));
}

MatchedErrors errors_against(const Multipliers& values, const Multipliers& reference,
                             const std::vector<double>& reference_precision) {
  if (reference_precision.size() != reference.size())
    throw BadInput("errors_against: " + std::to_string(reference.size()) + " reference values but " +
                   std::to_string(reference_precision.size()) + " precisions");
  const std::vector<int> a = match_by_proximity(reference, values);
  MatchedErrors out;
  for (size_t k = 0; k < reference.size(); ++k) {
    out.matched.push_back(values[a[k]]);
    out.errors.push_back(relative_error(values[a[k]], reference[k]));
    out.correct_digits.push_back(correct_digits(out.errors.back(), reference_precision[k]));
  }
  return out;
}

namespace {

// The analysis of successful levels (levels[i] at options.Ns[i], options validated).
ConvergenceStudy analyse_levels(const std::vector<LevelResult>& levels, const ConvergenceOptions& options) {
  const size_t L = options.Ns.size();
  const int nev = options.nev;
  if (levels.size() != L)
    throw BadInput("analyse_convergence: " + std::to_string(levels.size()) + " levels for " + std::to_string(L) + " N");
  for (size_t i = 0; i < L; ++i) {
    if (static_cast<int>(levels[i].multipliers.size()) < nev)
      throw NumericalFailure("convergence study: N = " + std::to_string(options.Ns[i]) + " gave " +
                             std::to_string(levels[i].multipliers.size()) + " multipliers, " + std::to_string(nev) +
                             " are tracked (nev)");
    if (!levels[i].accuracy.empty() && levels[i].accuracy.size() != levels[i].multipliers.size())
      throw BadInput("convergence study: N = " + std::to_string(options.Ns[i]) + " gave " +
                     std::to_string(levels[i].accuracy.size()) + " accuracies for " +
                     std::to_string(levels[i].multipliers.size()) + " multipliers");
  }

  ConvergenceStudy study;
  study.reference = options.reference;
  if (study.reference == ReferenceKind::automatic)
    study.reference =
        static_cast<int>(options.exact.size()) >= nev ? ReferenceKind::exact : ReferenceKind::extrapolated;
  const bool exact = study.reference == ReferenceKind::exact;

  // Anchors of the tracks: the exact values, or the finest level's leading nev.
  Multipliers anchors;
  if (exact) {
    anchors.assign(options.exact.begin(), options.exact.begin() + nev);
  } else {
    Multipliers finest = levels.back().multipliers;
    sort_by_modulus(finest);
    anchors.assign(finest.begin(), finest.begin() + nev);
  }
  // Match from the finest level down: each level against the next finer one.
  // A match is ambiguous where another candidate lies within twice the distance the track moves
  // there: the distance the matched one moved, or, if larger, the previous (finer) step's move
  // scaled by the expansion's leading term (h^p: (h_i^p - h_{i+1}^p) / (h_{i+1}^p - h_{i+2}^p), 4 for
  // p = 2 and halving), since a wrong partner can be nearer than the true one, which has moved that
  // far. Two multipliers closer than the discretisation moves them (the Pyragas orbit's two pairs
  // 1e-3 apart) can be swapped between levels, and extrapolating a swapped track gave bars
  // 1.2-3.6x short (issue 61 item 10). first_clear[k]: the coarsest level from which track k's
  // matches are all unambiguous; coarser levels are left out of its extrapolation.
  constexpr double kAmbiguity = 2;
  std::vector<double> previous_move(nev, 0);
  const double p = options.richardson.order;
  const auto hp = [&](size_t i) { return std::pow(1.0 / options.Ns[i], p); };
  std::vector<Multipliers> matched(L);
  std::vector<std::vector<double>> accuracy(L);  // of the matched values
  std::vector<size_t> first_clear(nev, 0);
  std::vector<bool> still_clear(nev, true);
  Multipliers targets = anchors;
  for (size_t step = 0; step < L; ++step) {
    const size_t i = L - 1 - step;
    const Multipliers& candidates = levels[i].multipliers;
    const std::vector<int> a = match_by_proximity(targets, candidates);
    matched[i].resize(nev);
    accuracy[i].resize(nev);
    for (int k = 0; k < nev; ++k) {
      matched[i][k] = candidates[a[k]];
      accuracy[i][k] = levels[i].accuracy.empty() ? options.richardson.input_precision * std::abs(matched[i][k])
                                                  : levels[i].accuracy[a[k]];
      if (step == 0 || !still_clear[k]) continue;  // the finest level is the anchor's own
      // (a candidate equal to the matched one within its accuracy, a double multiplier, swaps harmlessly)
      double moved = std::abs(matched[i][k] - targets[k]);
      if (i + 2 < L) moved = std::max(moved, previous_move[k] * (hp(i) - hp(i + 1)) / (hp(i + 1) - hp(i + 2)));
      previous_move[k] = std::abs(matched[i][k] - targets[k]);
      for (size_t j = 0; j < candidates.size(); ++j)
        if (static_cast<int>(j) != a[k] && std::abs(candidates[j] - targets[k]) < kAmbiguity * moved &&
            std::abs(candidates[j] - matched[i][k]) > 2 * accuracy[i][k]) {
          still_clear[k] = false;
          first_clear[k] = i + 1;
          break;
        }
    }
    targets = matched[i];
  }
  auto track = [&](int k) {
    std::vector<std::complex<double>> x(L);
    for (size_t i = 0; i < L; ++i) x[i] = matched[i][k];
    return x;
  };
  auto track_accuracy = [&](int k) {
    std::vector<double> a(L);
    for (size_t i = 0; i < L; ++i) a[i] = accuracy[i][k];
    return a;
  };
  std::vector<double> h(L);
  for (size_t i = 0; i < L; ++i) h[i] = 1.0 / options.Ns[i];  // relative step: h = tau / N

  // Extrapolated multipliers (every study with >= 2 levels reports them), each over its clear levels.
  if (L >= 2)
    for (int k = 0; k < nev; ++k) {
      const size_t from = first_clear[k];
      const auto tail = [&](auto v) { return decltype(v)(v.begin() + static_cast<long>(from), v.end()); };
      const Extrapolation e = richardson_extrapolate(tail(h), tail(track(k)), options.richardson, tail(track_accuracy(k)));
      std::string note = e.note;
      if (from > 0)
        note = "N = " + std::to_string(options.Ns[from - 1]) + (from > 1 ? " and coarser" : "") +
               " left out: matched ambiguously (another multiplier within twice the distance this one moved "
               "between levels); " + note;
      study.extrapolated.push_back({e.value, e.error_estimate, e.levels, note});
    }

  // The reference and its relative precision, per track.
  for (int k = 0; k < nev; ++k) {
    std::complex<double> ref;
    double precision = kMinPrecision;
    const double scale_floor = 1e-300;
    if (exact) {
      ref = options.exact[k];
      precision = std::max(options.exact_precision, kMinPrecision);
    } else if (study.reference == ReferenceKind::extrapolated) {
      ref = study.extrapolated[k].value;
      // relative; at most 1 (an infinite estimate certifies no digit)
      precision =
          std::clamp(study.extrapolated[k].error_estimate / std::max(std::abs(ref), scale_floor), kMinPrecision, 1.0);
    } else {  // finest: its own error estimated from the last two levels, e ~ |x_f - x_{f-1}| / (r^p - 1)
      ref = matched[L - 1][k];
      const double r = double(options.Ns[L - 1]) / options.Ns[L - 2];
      const double est = std::abs(matched[L - 1][k] - matched[L - 2][k]) / (std::pow(r, options.richardson.order) - 1);
      precision = std::max(est / std::max(std::abs(ref), scale_floor), kMinPrecision);
    }
    study.reference_values.push_back(ref);
    study.reference_precision.push_back(precision);
  }

  // Rows.
  for (size_t i = 0; i < L; ++i) {
    ConvergenceRow row;
    row.N = options.Ns[i];
    row.note = levels[i].note;
    row.multipliers = matched[i];
    row.seconds = levels[i].seconds;
    row.operator_applications = levels[i].operator_applications;
    for (int k = 0; k < nev; ++k) {
      const double e = relative_error(matched[i][k], study.reference_values[k]);
      row.errors.push_back(e);
      row.correct_digits.push_back(correct_digits(e, study.reference_precision[k]));
    }
    row.error = row.errors[0];
    study.seconds += row.seconds;
    study.rows.push_back(std::move(row));
  }

  // Orders.
  for (int k = 0; k < nev; ++k) {
    std::vector<double> e(L);
    for (size_t i = 0; i < L; ++i) e[i] = study.rows[i].errors[k];
    study.track_orders.push_back(
        track_order(options.Ns, track(k), e, exact, study.reference_precision[k], options.settled_spread));
  }
  study.order = study.track_orders[0];

  // Richardson columns of the leading track, with errors against the reference.
  RichardsonReport& rr = study.richardson;
  rr.Ns = options.Ns;
  const RichardsonTableau tab = richardson_tableau(h, track(0), options.richardson);
  const int columns = std::min<int>(static_cast<int>(L), options.richardson.max_columns);
  rr.columns.assign(columns, {});
  rr.errors.assign(columns, {});
  for (int j = 0; j < columns; ++j) {
    rr.expected_orders.push_back(tab.remaining_order(j));
    std::vector<double> log_n, log_e;
    const double floor = std::max(10 * study.reference_precision[0], kNoiseFloor);
    for (size_t i = j; i < L; ++i) {
      rr.columns[j].push_back(tab.T[i][j]);
      // An entry that combines the finest level with others is not independent of a finest or
      // extrapolated reference (column 0 is the level itself, its row error).
      const bool independent = exact || j == 0 || i + 1 < L;
      const double err = independent ? relative_error(tab.T[i][j], study.reference_values[0]) : kNaN;
      rr.errors[j].push_back(err);
      if (independent && err > floor) log_n.push_back(std::log(options.Ns[i])), log_e.push_back(std::log(err));
    }
    const double s = slope(log_n, log_e);
    rr.column_orders.push_back(std::isfinite(s) ? std::optional<double>(-s) : std::nullopt);
  }
  if (L >= 2) {
    const Extrapolation e = richardson_extrapolate(h, track(0), options.richardson, track_accuracy(0));
    rr.difference_orders.assign(e.column_orders.begin(), e.column_orders.begin() + columns);
    rr.consistent.assign(e.column_consistent.begin(), e.column_consistent.begin() + columns);
    rr.levels_used = e.levels;
  }
  return study;
}

}  // namespace

ConvergenceStudy analyse_convergence(const std::vector<LevelResult>& levels, const ConvergenceOptions& options) {
  validate(options);
  if (levels.size() != options.Ns.size())
    throw BadInput("analyse_convergence: " + std::to_string(levels.size()) + " levels for " +
                   std::to_string(options.Ns.size()) + " N");
  // The successful levels are analysed; the failed ones are reported in the rows.
  std::vector<LevelResult> ok;
  ConvergenceOptions sub = options;
  sub.Ns.clear();
  for (size_t i = 0; i < levels.size(); ++i)
    if (levels[i].failure.empty()) ok.push_back(levels[i]), sub.Ns.push_back(options.Ns[i]);
  const bool exact =
      options.reference == ReferenceKind::exact ||
      (options.reference == ReferenceKind::automatic && static_cast<int>(options.exact.size()) >= options.nev);
  const size_t needed = exact ? 1 : 2;
  if (ok.size() < needed)
    throw NumericalFailure("convergence study: " + std::to_string(ok.size()) + " of " + std::to_string(levels.size()) +
                           " levels succeeded, " + std::to_string(needed) + " needed" +
                           (exact ? "" : " without an exact reference") +
                           "; the failures:" + failures_text(options.Ns, levels));
  ConvergenceStudy study = analyse_levels(ok, sub);
  std::vector<ConvergenceRow> rows;
  size_t next = 0;
  for (size_t i = 0; i < levels.size(); ++i) {
    if (levels[i].failure.empty()) {
      rows.push_back(std::move(study.rows[next++]));
      continue;
    }
    ConvergenceRow row;
    row.N = options.Ns[i];
    row.failure = levels[i].failure;
    row.note = levels[i].note;
    row.error = kNaN;
    row.seconds = levels[i].seconds;
    row.operator_applications = levels[i].operator_applications;
    study.seconds += row.seconds;
    rows.push_back(std::move(row));
  }
  study.rows = std::move(rows);
  return study;
}

double multiplier_accuracy(std::complex<double> mu, double relative_residual, long n, long steps,
                           double spectral_radius) {
  constexpr double eps = std::numeric_limits<double>::epsilon();
  const double modulus = std::abs(mu);
  // |r| = |M v - mu v| / |v|, not below the rounding of computing M v (eps |M|, |M| >= |mu_1|: a
  // multiplier at round-off, even one reported as 0, is known to that much only); dense (no
  // residual): the QR algorithm's backward error n eps |M|
  const double residual = std::isfinite(relative_residual)
                              ? std::max(relative_residual * modulus, eps * spectral_radius)
                              : static_cast<double>(n) * eps * spectral_radius;
  const double kappa = 10 * std::sqrt(static_cast<double>(n));  // measured 0.4 .. 3.0 sqrt(n) (header)
  return kappa * residual + static_cast<double>(steps) * eps * modulus;
}

namespace {

using Clock = std::chrono::steady_clock;

// One call of a level (or retry) function; a NumericalFailure becomes a failed level.
template <class Call>
auto call_level(const Call& call) -> decltype(call()) {
  const auto start = Clock::now();
  try {
    return call();
  } catch (const NumericalFailure& e) {
    LevelResult r;
    r.failure = e.what();
    r.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return r;
  }
}

// Index of the successful level nearest in log N to level i (-1: none).
int nearest_success(const std::vector<int>& Ns, const std::vector<LevelResult>& levels, size_t i) {
  int best = -1;
  double distance = std::numeric_limits<double>::infinity();
  for (size_t j = 0; j < levels.size(); ++j) {
    const double d = std::abs(std::log(double(Ns[j]) / Ns[i]));
    if (levels[j].failure.empty() && d < distance) best = static_cast<int>(j), distance = d;
  }
  return best;
}

// Retries failed level i from the successful level `from`; keeps the first failure in the reason.
void retry_level(const RetryFunction& retry, const std::vector<int>& Ns, std::vector<LevelResult>& levels, size_t i,
                 int from, int count) {
  std::optional<LevelResult> again = call_level([&] { return retry(Ns[i], count, Ns[from]); });
  if (!again) return;  // no other way: the first failure stands
  LevelResult r = std::move(*again);
  r.seconds += levels[i].seconds;  // the failed attempt cost time too
  if (r.failure.empty()) {
    if (r.note.empty()) r.note = "retried from N = " + std::to_string(Ns[from]) + " after: " + levels[i].failure;
  } else {
    r.failure = levels[i].failure + "; retried from N = " + std::to_string(Ns[from]) + ": " + r.failure;
  }
  levels[i] = std::move(r);
}

// The largest relative error estimate of the tracked extrapolated multipliers (infinity: none).
double worst_relative_estimate(const ConvergenceStudy& s) {
  if (s.extrapolated.empty()) return std::numeric_limits<double>::infinity();
  double worst = 0;
  for (const auto& e : s.extrapolated) {
    const double scale = std::abs(e.value);
    const double rel = scale > 0 ? e.error_estimate / scale : std::numeric_limits<double>::infinity();
    worst = std::max(worst, std::isnan(rel) ? std::numeric_limits<double>::infinity() : rel);
  }
  return worst;
}

}  // namespace

ConvergenceStudy run_convergence_study(const LevelFunction& level, const ConvergenceOptions& options,
                                       const RetryFunction& retry) {
  validate(options);
  const int count = options.nev + options.extra;
  ConvergenceOptions o = options;  // o.Ns grows towards the target
  std::vector<LevelResult> levels;
  for (int N : o.Ns) levels.push_back(call_level([&] { return level(N, count); }));

  // Retries: nearest to a success first, each failed level once.
  if (retry) {
    std::vector<bool> retried(levels.size(), false);
    for (;;) {
      int best = -1, from = -1;
      double distance = std::numeric_limits<double>::infinity();
      for (size_t i = 0; i < levels.size(); ++i) {
        if (levels[i].failure.empty() || retried[i]) continue;
        const int j = nearest_success(o.Ns, levels, i);
        if (j < 0) continue;
        const double d = std::abs(std::log(double(o.Ns[j]) / o.Ns[i]));
        if (d < distance) best = static_cast<int>(i), from = j, distance = d;
      }
      if (best < 0) break;
      retried[best] = true;
      retry_level(retry, o.Ns, levels, best, from, count);
    }
  }
  ConvergenceStudy study = analyse_convergence(levels, o);
  if (!(o.target > 0)) return study;

  // Towards the target: double N while the estimate is above it and the limits allow.
  auto total_seconds = [&] {
    double t = 0;
    for (const auto& l : levels) t += l.seconds;
    return t;
  };
  for (;;) {
    const double worst = worst_relative_estimate(study);
    if (worst <= o.target) {
      study.target_met = true;
      study.stopped_by = StudyStop::target;
      study.stop_note =
          format_text("target %.3g met at N = %.0f: largest relative error estimate %.3g", o.target, o.Ns.back(), worst);
      return study;
    }
    study.target_met = false;
    const std::string unmet =
        (std::isfinite(worst) ? format_text("largest relative error estimate %.3g", worst) : std::string("no error estimate")) +
        format_text(" > target %.3g", o.target);
    const int last = o.Ns.back();
    if (last > o.max_N / 2) {
      study.stopped_by = StudyStop::max_N;
      study.stop_note = format_text("converge_max_N = %.0f reached (the next N would be %.0f): ", o.max_N, 2.0 * last) + unmet;
      return study;
    }
    // The next level's cost: the last one's times the growth of the last doubling (at least 2).
    const double t_last = levels.back().seconds;
    const double t_prev = levels.size() >= 2 ? levels[levels.size() - 2].seconds : 0;
    const double growth = t_prev > 0 ? std::max(2.0, t_last / t_prev) : 2.0;
    const double predicted = t_last * growth, spent = total_seconds();
    if (spent + predicted > o.max_seconds) {
      study.stopped_by = StudyStop::max_seconds;
      study.stop_note =
          format_text("converge_max_seconds = %.3g: the next level (N = %.0f) would take about %.3g s after %.3g s "
              "spent: ",
              o.max_seconds, 2.0 * last, predicted, spent) +
          unmet;
      return study;
    }
    const int N = 2 * last;
    o.Ns.push_back(N);
    levels.push_back(call_level([&] { return level(N, count); }));
    if (!levels.back().failure.empty() && retry) {
      const int from = nearest_success(o.Ns, levels, levels.size() - 1);
      if (from >= 0) retry_level(retry, o.Ns, levels, levels.size() - 1, from, count);
    }
    study = analyse_convergence(levels, o);
    if (!levels.back().failure.empty()) {
      const double now = worst_relative_estimate(study);
      study.target_met = now <= o.target;
      study.stopped_by = StudyStop::failure;
      study.stop_note = "level N = " + std::to_string(N) + " failed (" + levels.back().failure + ")";
      return study;
    }
  }
}

}  // namespace delayspec
