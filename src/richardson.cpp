#include "delayspec/richardson.hpp"

#include <cmath>
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

Extrapolation richardson_extrapolate(const std::vector<double>& h, const std::vector<std::complex<double>>& x,
                                     const RichardsonOptions& options) {
  const RichardsonTableau tab = richardson_tableau(h, x, options);
  const auto& last = tab.T.back();
  const int J = static_cast<int>(last.size()) - 1;
  Extrapolation e;
  e.value = last[J];
  e.levels = J + 1;
  e.remaining_order = tab.remaining_order(J);
  if (J == 0) {
    e.error_estimate = std::numeric_limits<double>::infinity();
    return e;
  }
  // Weights of value = sum_r w_r x_{L-1-J+r}: the first row of A^{-1}, i.e. A^T w = e_0.
  const int L = static_cast<int>(h.size());
  Eigen::MatrixXd A(J + 1, J + 1);
  for (int r = 0; r <= J; ++r) {
    A(r, 0) = 1;
    for (int k = 1; k <= J; ++k)
      A(r, k) = std::pow(h[L - 1 - J + r] / h[L - 1], options.order + (k - 1) * options.order_step);
  }
  const Eigen::VectorXd w = A.transpose().colPivHouseholderQr().solve(Eigen::VectorXd::Unit(J + 1, 0));
  double scale = 0;
  for (int r = 0; r <= J; ++r) scale = std::max(scale, std::abs(x[L - 1 - J + r]));
  e.amplification = w.cwiseAbs().sum();
  const double roundoff = options.input_precision * scale * e.amplification;  // |sum w_i dx_i| <= eps max|x| sum|w_i|
  e.error_estimate = std::max(std::abs(last[J] - last[J - 1]), roundoff);
  return e;
}

}  // namespace delayspec
