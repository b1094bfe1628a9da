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
// Example:
//   RichardsonOptions opt;                                   // order 2, step 2
//   auto best = richardson_extrapolate({0.1, 0.05, 0.025}, {x1, x2, x3}, opt);
//   // best.value ~ x0 + O(h^6), best.error_estimate ~ |T[2][2] - T[2][1]|
#include <complex>
#include <vector>

namespace delayspec {

struct RichardsonOptions {
  double order = 2;       // e_1: the leading error exponent
  double order_step = 2;  // e_{k+1} - e_k
  int max_columns = 4;    // at most this many levels are combined in one entry
  // Relative accuracy of each input value (eigen-solver round-off): the extrapolation amplifies it
  // by sum_i |w_i| (value = sum_i w_i x_i), which bounds the error estimate from below.
  double input_precision = 1e-14;
};

struct RichardsonTableau {
  std::vector<double> h;                                  // the steps, coarsest first
  std::vector<std::vector<std::complex<double>>> T;       // T[i][j], j = 0 .. min(i, max_columns - 1)
  // Error exponent of entry column j: what remains after eliminating e_1..e_j (= e_{j+1}).
  double remaining_order(int column) const { return order + column * order_step; }
  double order = 2, order_step = 2;
};

// Extrapolated value with an error estimate.
struct Extrapolation {
  std::complex<double> value;   // the finest entry of the highest column: T[L-1][J]
  double error_estimate = 0;    // max(|T[L-1][J] - T[L-1][J-1]|, the correction the last column made,
                                //     input_precision * max|x_i| * sum_i |w_i|, the amplified round-off);
                                // infinity when J = 0
  double amplification = 1;     // sum_i |w_i| of value = sum_i w_i x_i
  int levels = 0;               // levels combined in value (J + 1)
  double remaining_order = 0;   // the error exponent of value, e_{J+1}, if the expansion holds
};

// The whole tableau. BadInput: sizes differ, fewer than one level, steps not strictly
// decreasing and positive, a non-finite value, order or order_step <= 0, max_columns < 1.
RichardsonTableau richardson_tableau(const std::vector<double>& h, const std::vector<std::complex<double>>& x,
                                     const RichardsonOptions& options = {});

// The best entry of the tableau and its error estimate (see Extrapolation).
Extrapolation richardson_extrapolate(const std::vector<double>& h, const std::vector<std::complex<double>>& x,
                                     const RichardsonOptions& options = {});

}  // namespace delayspec
