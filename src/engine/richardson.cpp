#include "delayspec/richardson.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include <Eigen/Dense>

#include "delayspec/errors.hpp"

namespace delayspec {

namespace {

void validate(const std::vector<double>& h, const std::vector<std::complex<double>>& x,
              const RichardsonOptions& options) {
  if (h.size() != x.size())
    throw BadInput("richardson: " + std::to_string(h.size()) + " steps but " + std::to_string(x.size()) + " values");
  if (h.empty()) throw BadInput("richardson: no levels");
  if (!(options.order > 0) || !std::isfinite(options.order))
    throw BadInput("richardson: `order = " + format_number(options.order) + "`: must be > 0");
  if (!(options.order_step > 0) || !std::isfinite(options.order_step))
    throw BadInput("richardson: `order_step = " + format_number(options.order_step) + "`: must be > 0");
  if (options.max_columns < 1)
    throw BadInput("richardson: `max_columns = " + std::to_string(options.max_columns) + "`: must be >= 1");
  for (size_t i = 0; i < h.size(); ++i) {
    if (!(h[i] > 0) || !std::isfinite(h[i]) || (i > 0 && !(h[i] < h[i - 1])))
      throw BadInput("richardson: steps must be positive and strictly decreasing (h[" + std::to_string(i) +
                     "] = " + format_number(h[i]) + ")");
    if (!std::isfinite(x[i].real()) || !std::isfinite(x[i].imag()))
      throw BadInput("richardson: value " + std::to_string(i) + " is not finite");
  }
}

// A first column that converges faster than the expansion's leading term h^q allows (pair order
// above q + tol) may still carry that term: with a switch inside a step (events = off) its
// coefficient depends on where the switch falls in its step, theta = frac(t_s / h), and doubling
// N maps theta to 2 theta mod 1; while theta is small the term c theta h stays nearly constant, so
// it moves no difference and then reappears. Measured: the impact orbit at tau = T, k = 0.55,
// events = off showed order 2.0 over N = 3200 .. 25600 (differences 1.2e-5, 3.1e-6, 7.7e-7), and
// the last differences claimed 3.8e-6 for an error of 8.4e-5 (issue 61 item 10).
// So the last differences are accepted only after a long run of triples shows the faster order
// (kLongRun: theta within 2^-7 of a node at every level of the run, about 1 % per switch). Shorter,
// the term is bounded by its size where it showed: the largest difference of the column, each
// scaled to the finest step by (h_L / h_i)^q (as for a wandering coefficient in a higher column,
// richardson_extrapolate); if no triple shows it, nothing bounds it.
struct HiddenTerm {
  double spread = 0;        // the scaled largest difference (0: a long run showed the faster order)
  bool never_seen = false;  // fewer than kLongRun triples, none of them at order <= q + tol
};

template <class Entry>
HiddenTerm hidden_leading_term(const std::vector<double>& h, double last_order, double q, double tol,
                               Entry entry) {
  constexpr int kLongRun = 6;
  HiddenTerm hidden;
  const int L = static_cast<int>(h.size());
  if (!(last_order > q + tol)) return hidden;
  int run = 0;  // triples ending at the finest level that show an order above q + tol
  bool seen = false;
  for (int i = L - 3; i >= 0; --i) {
    const double d1 = std::abs(entry(i + 1) - entry(i)), d2 = std::abs(entry(i + 2) - entry(i + 1));
    if (d1 == 0) continue;  // no order to read
    const bool faster = d2 == 0 || order_of_differences(h[i], h[i + 1], h[i + 2], d1, d2) > q + tol;
    if (faster && !seen) ++run;
    if (!faster) seen = true;
  }
  if (run >= kLongRun) return hidden;
  hidden.never_seen = !seen;
  for (int i = 1; i < L; ++i)
    hidden.spread = std::max(hidden.spread, std::abs(entry(i) - entry(i - 1)) * std::pow(h[L - 1] / h[i], q));
  return hidden;
}

}  // namespace

RichardsonTableau richardson_tableau(const std::vector<double>& h, const std::vector<std::complex<double>>& x,
                                     const RichardsonOptions& options) {
  validate(h, x, options);
  RichardsonTableau tab;
  tab.h = h;
  tab.order = options.order;
  tab.order_step = options.order_step;
  const int L = static_cast<int>(h.size());
  tab.T.resize(L);
  for (int i = 0; i < L; ++i) {
    const int J = std::min(i, options.max_columns - 1);
    tab.T[i].resize(J + 1);
    tab.T[i][0] = x[i];
    for (int j = 1; j <= J; ++j) {
      // Unknowns (x0, c_1 .. c_j); row r (level i - j + r):  x0 + sum_k c_k (h_r / h_i)^{e_k} = x_r.
      // Scaling by h_i keeps the entries O(1) .. O((h_coarse/h_fine)^{e_j}).
      Eigen::MatrixXd A(j + 1, j + 1);
      Eigen::MatrixXd b(j + 1, 2);
      for (int r = 0; r <= j; ++r) {
        const int level = i - j + r;
        A(r, 0) = 1;
        for (int k = 1; k <= j; ++k) A(r, k) = std::pow(h[level] / h[i], options.order + (k - 1) * options.order_step);
        b(r, 0) = x[level].real();
        b(r, 1) = x[level].imag();
      }
      const Eigen::MatrixXd sol = A.colPivHouseholderQr().solve(b);
      tab.T[i][j] = {sol(0, 0), sol(0, 1)};
    }
  }
  return tab;
}

namespace {

// Weights of T[last][j] = sum_r w_r x_{last-j+r}: the first row of A^{-1}, i.e. A^T w = e_0.
Eigen::VectorXd column_weights(const std::vector<double>& h, int last, int j, const RichardsonOptions& options) {
  Eigen::MatrixXd A(j + 1, j + 1);
  for (int r = 0; r <= j; ++r) {
    A(r, 0) = 1;
    for (int k = 1; k <= j; ++k)
      A(r, k) = std::pow(h[last - j + r] / h[last], options.order + (k - 1) * options.order_step);
  }
  return A.transpose().colPivHouseholderQr().solve(Eigen::VectorXd::Unit(j + 1, 0));
}

}  // namespace

// d2 / d1 for three levels h0 > h1 > h2 of a sequence whose error is exactly C h^p:
// (h1^p - h2^p) / (h0^p - h1^p); r^-p for equal ratios r = h0/h1 = h1/h2.
double difference_ratio(double h0, double h1, double h2, double p) {
  return (std::pow(h1, p) - std::pow(h2, p)) / (std::pow(h0, p) - std::pow(h1, p));
}

// The order p with difference_ratio(h0, h1, h2, p) = d2 / d1 (log(d1 / d2) / log r for equal
// ratios), by bisection: the ratio falls with p. Levels 25, 50, 200 of an h^2 sequence give
// d1 / d2 = 3.2, not 2.83^2 = 8 (the geometric mean ratio): the formula for equal ratios would
// call it order 1.1.
double order_of_differences(double h0, double h1, double h2, double d1, double d2) {
  const double target = d2 / d1;
  double lo = 1e-3, hi = 30;
  if (difference_ratio(h0, h1, h2, lo) <= target || difference_ratio(h0, h1, h2, hi) >= target)
    return std::log(d1 / d2) / std::log(std::sqrt(h0 / h2));  // outside (0, 30]: the equal-ratio formula
  for (int it = 0; it < 100 && hi - lo > 1e-12; ++it) {
    const double mid = 0.5 * (lo + hi);
    (difference_ratio(h0, h1, h2, mid) > target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

Extrapolation richardson_extrapolate(const std::vector<double>& h, const std::vector<std::complex<double>>& x,
                                     const RichardsonOptions& options, const std::vector<double>& input_errors) {
  if (!(options.order_tolerance > 0) || !std::isfinite(options.order_tolerance))
    throw BadInput("richardson: `order_tolerance = " + format_number(options.order_tolerance) + "`: must be > 0");
  const RichardsonTableau tab = richardson_tableau(h, x, options);
  const int L = static_cast<int>(h.size());
  if (!input_errors.empty() && input_errors.size() != h.size())
    throw BadInput("richardson: " + std::to_string(input_errors.size()) + " input errors for " + std::to_string(L) +
                   " levels");
  std::vector<double> accuracy(L);  // a_i: absolute accuracy of x_i
  for (int i = 0; i < L; ++i) {
    accuracy[i] = input_errors.empty() ? options.input_precision * std::abs(x[i]) : input_errors[i];
    if (!(accuracy[i] >= 0))
      throw BadInput("richardson: input error " + std::to_string(i) + " = " + format_number(accuracy[i]) +
                     ": must be >= 0");
  }
  const int top = static_cast<int>(tab.T.back().size()) - 1;  // highest column available
  auto entry = [&](int i, int j) { return tab.T[i][j]; };
  // Round-off of column j's finest entry: |sum_r w_r dx_r| <= sum_r |w_r| a_r (the coarser entries
  // of the column, made of coarser levels, carry no more).
  std::vector<double> noise(top + 1), amplification(top + 1);
  for (int j = 0; j <= top; ++j) {
    const Eigen::VectorXd w = column_weights(h, L - 1, j, options);
    amplification[j] = w.cwiseAbs().sum();
    noise[j] = 0;
    for (int r = 0; r <= j; ++r) noise[j] += std::abs(w(r)) * accuracy[L - 1 - j + r];
  }

  // Column checks (header comment): the last two triples of each column (or its only one).
  // plateau[j]: in those triples a difference fell far faster than any order the expansion
  // allows (pair order > 2 e + 1), or to round-off after a difference above it, or jumped up
  // after a flat stretch (pair order < -1). The value then moves in jumps (the impact orbit with
  // events = off: piecewise constant in N while the set of grid nodes in contact stays the
  // same), and small last differences say nothing of the next jump: measured on 200, 400, 800,
  // 1600, an estimate of 4.7e-4 for an error of 1.2e-2 (issue 32, item 3).
  Extrapolation e;
  std::vector<bool> plateau(top + 1, false);
  for (int j = 0; j <= top; ++j) {
    const int entries = L - j;
    if (entries < 3) {
      e.column_orders.push_back(std::numeric_limits<double>::quiet_NaN());
      e.column_consistent.push_back(-1);
      continue;
    }
    const double expected = tab.remaining_order(j);
    bool consistent = true;
    double last_order = std::numeric_limits<double>::quiet_NaN();
    for (int i = std::max(j, L - 4); i + 2 <= L - 1; ++i) {  // triple (i, i + 1, i + 2)
      const double d1 = std::abs(entry(i + 1, j) - entry(i, j)), d2 = std::abs(entry(i + 2, j) - entry(i + 1, j));
      const double tol = options.order_tolerance;
      const double low = d1 * difference_ratio(h[i], h[i + 1], h[i + 2], expected + tol);
      const double high = d1 * difference_ratio(h[i], h[i + 1], h[i + 2], expected - tol);
      consistent = consistent && d2 <= high + 2 * noise[j] && d2 >= low - 2 * noise[j];
      last_order = d1 > 0 && d2 > 0 ? order_of_differences(h[i], h[i + 1], h[i + 2], d1, d2)
                                    : std::numeric_limits<double>::quiet_NaN();
      if (d1 > 2 * noise[j])
        plateau[j] = plateau[j] || d2 <= 2 * noise[j] || last_order > 2 * expected + 1 || last_order < -1;
    }
    e.column_orders.push_back(last_order);
    e.column_consistent.push_back(consistent ? 1 : 0);
  }

  // J: the first column not shown consistent (inconsistent or unchecked), else the highest.
  int J = top;
  if (options.check_orders)
    for (int j = 0; j < top; ++j)
      if (e.column_consistent[j] != 1) {
        J = j;
        break;
      }
  const bool failed = options.check_orders && e.column_consistent[J] == 0;
  e.value = entry(L - 1, J);
  e.levels = J + 1;
  e.remaining_order = tab.remaining_order(J);
  e.amplification = amplification[J];
  e.roundoff = noise[J];
  const double roundoff = e.roundoff;
  if (failed && J >= 1) {
    // Column J - 1 shows its order q, column J not its own: the term of order q does not have a
    // constant coefficient (an event's place in the grid changes it from level to level), so
    // column J removed its mean and kept a wandering part, T[i][J] = x0 + delta_i h_i^q with
    // |delta_i| <= Delta. Its differences then say how large Delta is:
    // |T[i][J] - T[i-1][J]| = |delta_i h_i^q - delta_{i-1} h_{i-1}^q|, and each, scaled to the
    // finest step by (h_{L-1} / h_i)^q, is of the size Delta h_{L-1}^q (up to 1 + r^q times it
    // when the two deltas have opposite signs). The maximum over the column's last four entries
    // (those its order check looked at: earlier levels may be pre-asymptotic, and on the impact
    // orbit over N = 100 .. 3200 they made the bar 40x the error instead of 4x) covers the finest
    // entry's error unless every earlier delta came out well below the finest one: with deltas
    // drawn independently and uniformly from [-Delta, Delta] it covered it in 98.1 % of draws
    // with 4 levels and 99.5 % with 5 or more (20000 draws each), about 7x above it at the
    // median. Growing or jumping differences are expected here, not a failure.
    const double q = tab.remaining_order(J - 1);
    double spread = 0;
    for (int i = std::max(J, L - 4) + 1; i <= L - 1; ++i)  // the entries the column checks looked at
      spread = std::max(spread, std::abs(entry(i, J) - entry(i - 1, J)) * std::pow(h[L - 1] / h[i], q));
    e.error_estimate = std::max(spread, roundoff);
    e.note = format_text("column %.0f (%.0f levels) shows order %.3g over its last entries, expected %.3g, ", J + 1.0, J + 1.0,
                 e.column_orders[J], tab.remaining_order(J)) +
             format_text("while column %.0f shows its order %.3g: ", J + 0.0, q) +
             (J + 1 <= top ? "higher columns not used; " : "") +
             format_text("the order-%.3g term's coefficient wanders from level to level (events moving across the grid): "
                 "error from the spread of column %.0f's last entries, each scaled to the finest step like h^%.3g",
                 q, J + 1.0, q);
    return e;
  }
  if (failed) {
    // Column 0 itself inconsistent: its tail, max(d_last, d_prev) (the header comment).
    const double d_last = std::abs(entry(L - 1, 0) - entry(L - 2, 0));
    const double d_prev = std::abs(entry(L - 2, 0) - entry(L - 3, 0));
    // Faster than the expansion's leading term allows: where its coefficient depends on a switch's
    // place in the step, that term may be hidden rather than absent (hidden_leading_term). A
    // constant coefficient cannot come back once small: the tail below holds then.
    const double q = tab.remaining_order(0);
    const HiddenTerm hidden = options.leading_term_may_hide
                                  ? hidden_leading_term(h, e.column_orders[0], q, options.order_tolerance,
                                                        [&](int i) { return entry(i, 0); })
                                  : HiddenTerm{};
    // Growing differences, or a plateau (above), or a leading term never seen: no estimate.
    std::string why;
    if ((d_last > d_prev && d_last > 2 * roundoff) || plateau[0] || hidden.never_seen) {
      e.error_estimate = std::numeric_limits<double>::infinity();
    } else {
      e.error_estimate = std::max({d_last, d_prev, hidden.spread, roundoff});
    }
    e.note = format_text("column 1 (1 level, no extrapolation) shows order %.3g over its last entries, expected %.3g: ",
                 e.column_orders[0], q) +
             (top >= 1 ? "higher columns not used; " : "") +
             (plateau[0] ? "its differences fall far faster than that order allows (a plateau, the value moves in "
                           "jumps): no error estimate"
              : std::isinf(e.error_estimate) && !hidden.never_seen ? "its differences grow: no error estimate"
              : hidden.never_seen
                  ? format_text("no level shows the order-%.3g term and %.0f level(s) are too few to rule it out (it can "
                        "hide behind a switch that sits near the same place in its step at every level): no error "
                        "estimate (more levels, coarser or finer, or events = on)",
                        q, static_cast<double>(h.size()))
              : hidden.spread > std::max(d_last, d_prev)
                  ? format_text("the order-%.3g term showed at coarser levels and may be hidden at these: error from the "
                        "largest difference of the column, each scaled to the finest step like h^%.3g",
                        q, q)
                  : "error from that column's last differences");
    return e;
  }
  if (J == 0) {  // column 0 unchecked (fewer than three levels) or the only one
    e.error_estimate = std::numeric_limits<double>::infinity();
    e.note = L < 3 ? format_text("%.0f level(s): the order cannot be checked (three levels needed): no extrapolation, no error "
                         "estimate",
                         L)
                   : "one column only: no extrapolation, no error estimate";
    return e;
  }
  e.error_estimate = std::max(std::abs(entry(L - 1, J) - entry(L - 1, J - 1)), roundoff);
  e.note = !options.check_orders ? format_text("%.0f levels (orders not checked)", J + 1.0)
           : J < top             ? format_text("%.0f levels: every column below shows its expected order; column %.0f has too "
                                                   "few entries to check, so it is not built upon (more N would allow more levels)",
                                       J + 1.0, J + 1.0)
                                 : format_text("%.0f levels: every column below shows its expected order", J + 1.0);
  return e;
}

}  // namespace delayspec
