#pragma once
// Richardson extrapolation of a sequence computed at several steps h_i, with an error estimate.
//
// Assumed error expansion (design.md 1.8):
//
//     x(h) = x0 + c_1 h^{e_1} + c_2 h^{e_2} + ...,      e_k = order + (k - 1) order_step.
//
// The trapezoidal rule on a smooth problem is symmetric, its error is even in h: order = 2,
// order_step = 2. Then one level gives O(h^2), two levels O(h^4), three O(h^6), ...
//
// Tableau: T[i][j] is the value at h = 0 of the fit x0 + sum_{k=1..j} c_k h^{e_k} through the
// j + 1 levels i - j, ..., i (levels ordered from the coarsest to the finest). T[i][0] = x_i.
// For e_k = k q (order = order_step) this is Neville's scheme in s = h^q, exact for any steps;
// the small linear system solved here covers the general case too.
//
// Which column to trust (check_orders, the default). The expansion is an assumption; a step
// split at an event, for one, has a clean h^2 term and then non-smooth terms (docs/events.md),
// and eliminating h^4, h^6 there removes nothing real while the error estimate (the last
// correction) shrinks as if it had: measured on the impact orbit, 4 columns claimed 1.8e-6 for
// a value off by 3.1e-5. So every column is checked against the data before it is built upon:
//   * Column j's entries T[j..L-1][j] should converge like h^{e_{j+1}}: for three consecutive
//     entries at h0 > h1 > h2 with differences d1 (coarser), d2, d2 = d1 rho(e_{j+1}),
//     rho(p) = (h1^p - h2^p) / (h0^p - h1^p) (= r^-p for equal step ratios r; levels 25, 50,
//     200 need the general form). The column is consistent when its last two triples
//     (or its only one) satisfy d1 rho(e + tol) - 2 noise <= d2 <= d1 rho(e - tol) + 2 noise,
//     tol = order_tolerance, noise = sum_i |w_i| a_i (an entry's round-off: w the weights of
//     the entry, a_i the accuracy of input i, `input_errors` or input_precision |x_i|; at the
//     round-off floor any column passes, and further columns change nothing).
//     A column with fewer than three entries cannot be checked.
//   * The value is the finest entry of column J, J = the first column that is not consistent
//     (inconsistent, or too short to check), or the highest column if all are consistent.
//     Only a consistent column is built upon: an unchecked column's order is not known, and
//     eliminating the next term from it is what made 3 levels of the PWSDDE period-2 orbit
//     claim 1.7e-6 for a value off by 6.1e-6 (the unchecked two-level column converged at
//     order 2.2, not 4).
//     Why a consistent column J - 1 justifies column J: eliminating h^e from a sequence whose
//     error is really C h^p leaves the fraction |1 - (r^p - 1) / (r^e - 1)| of it: at most 31 %
//     for |p - e| <= 0.3, r = 2, e = 2 (less for higher e), so the last correction
//     |T[L-1][J] - T[L-1][J-1]| (the error of T[L-1][J-1]) still exceeds the remaining error
//     of T[L-1][J] by 2x or more: that is the error estimate when column J is consistent or
//     unchecked (the textbook estimate), never below the round-off of T[L-1][J].
//   * When column 0 itself is inconsistent, its error is estimated from its own last entries:
//     E = max(d_last, d_prev). If the column converges at least at first order from here on
//     (each later difference at most half the previous one, r = 2), its remaining error is
//     <= d_last; d_prev stops a d_last that is small by an accidental cancellation from passing
//     as accuracy. When its differences grow (d_last > d_prev, above round-off), no estimate is
//     possible: infinity. Nor when, in its last two triples, a difference falls far faster than
//     the expansion allows (pair order > 2 e_1 + 1), to round-off after one above it, or jumps
//     up after a flat stretch (pair order < -1): a plateau, whose small last differences say
//     nothing of the next jump (the impact orbit with events = off).
//     With leading_term_may_hide (events = off on a switching model) a column 0 converging faster
//     than h^{e_1} is believed only after six triples show it: the h^{e_1} term, whose size
//     depends on where a switch falls in its step, can stay constant for several levels and come
//     back. Before that, E is at least the column's largest difference scaled to the finest step
//     like h^{e_1}, and infinity when no triple shows the h^{e_1} term (richardson.cpp).
//   * When column J >= 1 is inconsistent, column J - 1 showed its order q = e_J: the data have
//     an h^q term, but its coefficient is not constant (an event's place in the grid changes it
//     from level to level: the impact orbit's raw order wanders over 1.89 .. 2.10). Column J
//     removed its mean and kept the wandering part, T[i][J] = x0 + delta_i h_i^q, |delta_i| <=
//     Delta, whose differences can grow, shrink or jump. Its error is bounded by the spread:
//     E = max over the column's last four entries of |T[i][J] - T[i-1][J]| (h_{L-1} / h_i)^q, each
//     difference scaled to the finest step like h^q (of the size Delta h_{L-1}^q; the .cpp says
//     how often it covers the error). Checked against the impact orbit's exact multipliers at
//     tau = T (tests/cli/test_cli_converge.cpp).
//   With check_orders = false the highest column is used with the textbook estimate.
//
// Example:
//   RichardsonOptions opt;                                   // order 2, step 2
//   auto best = richardson_extrapolate({0.1, 0.05, 0.025}, {x1, x2, x3}, opt);
//   // best.value ~ x0 + O(h^6), best.error_estimate ~ |T[2][2] - T[2][1]|
#include <complex>
#include <string>
#include <vector>

namespace delayspec {

struct RichardsonOptions {
  double order = 2;       // e_1: the leading error exponent
  double order_step = 2;  // e_{k+1} - e_k
  int max_columns = 4;    // at most this many levels are combined in one entry
  // Relative accuracy of each input value when richardson_extrapolate gets no `input_errors`: the
  // extrapolation amplifies it by sum_i |w_i| (value = sum_i w_i x_i), which bounds the error
  // estimate from below.
  double input_precision = 1e-14;
  bool check_orders = true;      // use a column only if the column below shows its expected order (above)
  double order_tolerance = 0.3;  // |observed - expected| order allowed by that check
  // The h^order term's coefficient depends on where a switch falls inside its step (events = off
  // on a switching model): it can vanish for several levels and come back, so a first column that
  // converges faster than h^order is not taken at its word (richardson.cpp, hidden_leading_term).
  bool leading_term_may_hide = false;
};

struct RichardsonTableau {
  std::vector<double> h;                             // the steps, coarsest first
  std::vector<std::vector<std::complex<double>>> T;  // T[i][j], j = 0 .. min(i, max_columns - 1)
  // Error exponent of entry column j: what remains after eliminating e_1..e_j (= e_{j+1}).
  double remaining_order(int column) const { return order + column * order_step; }
  double order = 2, order_step = 2;
};

// Extrapolated value with an error estimate.
struct Extrapolation {
  std::complex<double> value;          // the finest entry of the column used: T[L-1][J] (J: header comment)
  double error_estimate = 0;           // max(|T[L-1][J] - T[L-1][J-1]|, the correction the last column made,
                                       //     sum_i |w_i| a_i, the amplified accuracy of the inputs);
                                       // when column J is inconsistent: max(its tail (J = 0) or spread
                                       // (J >= 1) estimate, round-off); infinity when J = 0 and column 0
                                       // cannot be checked, its differences grow, or it is a plateau
  std::vector<double> column_orders;   // per column: order from its last three entries, the p with
                                       // rho(p) = d2 / d1 (log(d1 / d2) / log r for equal ratios r; NaN
                                       // with fewer than three entries or a zero difference)
  std::vector<int> column_consistent;  // per column: 1 consistent, 0 inconsistent, -1 not checkable
  std::string note;                    // why column J, in words with the numbers
  double amplification = 1;            // sum_i |w_i| of value = sum_i w_i x_i
  double roundoff = 0;                 // sum_i |w_i| a_i of value: the floor of error_estimate
  int levels = 0;                      // levels combined in value (J + 1)
  double remaining_order = 0;          // the error exponent of value, e_{J+1}, if the expansion holds
};

// d2 / d1 for three levels h0 > h1 > h2 of a sequence whose error is exactly C h^p.
double difference_ratio(double h0, double h1, double h2, double p);
// The order shown by the differences d1 = |x1 - x0|, d2 = |x2 - x1| at h0 > h1 > h2: the p with
// difference_ratio(h0, h1, h2, p) = d2 / d1 (log(d1 / d2) / log r for equal step ratios r).
double order_of_differences(double h0, double h1, double h2, double d1, double d2);

// The whole tableau. BadInput: sizes differ, fewer than one level, steps not strictly
// decreasing and positive, a non-finite value, order or order_step <= 0, max_columns < 1.
RichardsonTableau richardson_tableau(const std::vector<double>& h, const std::vector<std::complex<double>>& x,
                                     const RichardsonOptions& options = {});

// The best entry of the tableau and its error estimate (see Extrapolation). input_errors[i], when
// given (one per level, >= 0), is the absolute accuracy of x[i] (e.g. multiplier_accuracy,
// convergence.hpp); empty: options.input_precision |x_i|. BadInput: wrong size, negative or NaN.
Extrapolation richardson_extrapolate(const std::vector<double>& h, const std::vector<std::complex<double>>& x,
                                     const RichardsonOptions& options = {},
                                     const std::vector<double>& input_errors = {});

}  // namespace delayspec
