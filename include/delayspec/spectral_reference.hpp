#pragma once
// A spectral reference for the Floquet multipliers (issue 58 item 5): piecewise Chebyshev
// collocation of the monodromy (Bueler; Butcher et al.; Breda's piecewise pseudospectral method),
// a dense discretisation that shares nothing with the step maps but the model's A and B. For a
// linear time-periodic model with one delay tau = T:
//
//     y'(t) = A(t) y(t) + B(t) y(t - T).
//
// The period [0, T] is cut at every time switch of the model (model_grid.hpp) and, within, into
// `pieces` equal parts; on each piece [a, b] the solution is the polynomial of degree n through
// the Chebyshev-Lobatto nodes t_k = a + (b - a)(1 - cos(pi k / n)) / 2, k = 0..n, and satisfies
// the equation at t_1..t_n, in the branch of the open piece (its formula holds at the ends):
//
//     sum_j (2 / (b - a)) D_kj y_j = A(t_k) y_k + B(t_k) y(t_k - T),   y_0 = the end of the last piece,
//
// D the differentiation matrix on [-1, 1] (barycentric: D_kj = (w_j / w_k) / (x_k - x_j), D_kk =
// -sum_j D_kj). With tau = T the delayed value at a node is the history's value at the same node
// one period earlier, so the history is the vector U of y at the 1 + P n distinct nodes of
// [-T, 0] (P pieces), and one period maps it to the same nodes of [0, T]: U' = M U, M dense of
// size d (1 + P n). Its eigenvalues converge geometrically in n where A and B are smooth on every
// piece (the switches are the pieces' ends): the error estimate is their difference between
// degree n and degree n + `degree_step` (the coarser's error, an overestimate of the finer's).
//
// Only linear models (is_linear: the monodromy does not depend on the orbit; A and B taken at
// y = 0) with one delay equal to the period: BadInput otherwise, naming what is not so.
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "delayspec/dense_spectrum.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/model.hpp"
#include "delayspec/model_grid.hpp"

namespace delayspec {

struct SpectralOptions {
  int degree = 16;       // n, the polynomial degree per piece (>= 2)
  int degree_step = 8;   // the second degree, n + degree_step, for the error estimate (>= 1)
  int pieces = 1;        // equal parts of each interval between switches (>= 1)
  int nev = 6;           // multipliers returned, largest modulus first
  DenseBackend backend = DenseBackend::lapack;
};

struct SpectralResult {
  std::vector<std::complex<double>> multipliers;  // at degree n + degree_step, largest modulus first
  std::vector<double> error_estimate;             // per multiplier: |mu(n + step) - mu(n)|, the nearest at n
  long dimension = 0;                             // of M at degree n + degree_step: d (1 + P n)
  std::vector<double> breakpoints;                // the pieces' starts in [0, T)
};

namespace detail {

// The Chebyshev-Lobatto points of [-1, 1] in ascending order and their differentiation matrix.
inline void chebyshev_lobatto(int n, Eigen::VectorXd& x, Eigen::MatrixXd& D) {
  x.resize(n + 1);
  Eigen::VectorXd w(n + 1);
  for (int k = 0; k <= n; ++k) {
    x[k] = -std::cos(std::numbers::pi * k / n);
    w[k] = (k % 2 == 0 ? 1.0 : -1.0) * (k == 0 || k == n ? 0.5 : 1.0);
  }
  D.setZero(n + 1, n + 1);
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j)
      if (i != j) D(i, j) = (w[j] / w[i]) / (x[i] - x[j]);
    D(i, i) = -D.row(i).sum();  // the rows of D annihilate constants
  }
}

// A diagonal scaling s (powers of 2, exact) that balances the model's A, B at the pieces'
// midpoints (Osborne's iteration on the sum of |A| + |B|): the collocation is done for z with
// y = diag(s) z, whose A and B are diag(s)^-1 A diag(s). A physical state mixes scales (milling:
// x in m, x' = omega_n x with omega_n ~ 6e3) and the unscaled system's rows differ by omega_n^2:
// measured, its multipliers stall at ~5e-11 relative whatever the degree; balanced, near 1e-14.
template <class Model>
Vec<Model::d> balancing_scale(const Model& model, const std::vector<double>& starts, double T) {
  constexpr int d = Model::d;
  Mat<d> C = Mat<d>::Zero();
  const Vec<d> zero = Vec<d>::Zero();
  const DelayedVec<Model> w0 = DelayedVec<Model>::Zero();
  for (size_t p = 0; p < starts.size(); ++p) {
    const double a = starts[p], b = p + 1 < starts.size() ? starts[p + 1] : T, t = 0.5 * (a + b);
    int branch = 1;
    if constexpr (TimeSwitchedModel<Model>) branch = model.time_segment(t);
    C += model.A(branch, t, zero, w0).cwiseAbs() + model.B(branch, t, zero, w0).cwiseAbs();
  }
  Vec<d> s = Vec<d>::Ones();
  for (int sweep = 0; sweep < 20; ++sweep) {
    bool changed = false;
    for (int i = 0; i < d; ++i) {
      double row = 0, col = 0;  // off-diagonal sums of diag(s)^-1 C diag(s)
      for (int j = 0; j < d; ++j)
        if (j != i) row += C(i, j) * s[j] / s[i], col += C(j, i) * s[i] / s[j];
      if (row == 0 || col == 0) continue;
      const double f = std::exp2(std::round(0.5 * std::log2(row / col)));  // balances row and column
      if (f != 1) s[i] *= f, changed = true;
    }
    if (!changed) break;
  }
  return s;
}

// M at degree n over the pieces starting at `starts` (ascending, starts[0] = 0) of [0, T), for the
// state scaled by s (y = diag(s) z: the same eigenvalues).
template <class Model>
Eigen::MatrixXd spectral_monodromy(const Model& model, const std::vector<double>& starts, double T, int n) {
  constexpr int d = Model::d;
  const long P = static_cast<long>(starts.size()), nodes = 1 + P * n, dim = d * nodes;
  Eigen::VectorXd x;
  Eigen::MatrixXd D;
  chebyshev_lobatto(n, x, D);
  const Vec<d> zero = Vec<d>::Zero();
  const DelayedVec<Model> w0 = DelayedVec<Model>::Zero();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(dim, dim);
  // Row block of node 0 (t = 0): y(0) = the history's last node (t = 0 of the previous period).
  M.block(0, dim - d, d, d).setIdentity();
  Eigen::MatrixXd left = M.topRows(d);  // y at the current piece's left end, as rows over U
  const Vec<d> s = balancing_scale(model, starts, T);
  const Mat<d> ratio = s.cwiseInverse() * s.transpose();  // (diag(s)^-1 X diag(s))_ij = X_ij s_j / s_i
  for (long p = 0; p < P; ++p) {
    const double a = starts[static_cast<size_t>(p)], b = p + 1 < P ? starts[static_cast<size_t>(p + 1)] : T;
    const double scale = 2 / (b - a);
    int branch = 1;
    if constexpr (TimeSwitchedModel<Model>) branch = model.time_segment(0.5 * (a + b));
    // S X = C left + G U: X the nodes 1..n of the piece (n d rows over U)
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(n * d, n * d), rhs = Eigen::MatrixXd::Zero(n * d, dim);
    for (int k = 1; k <= n; ++k) {
      const double t = a + (b - a) * (1 + x[k]) / 2;
      const Mat<d> A = model.A(branch, t, zero, w0).cwiseProduct(ratio);
      const Mat<d> B = model.B(branch, t, zero, w0).cwiseProduct(ratio);
      const long row = static_cast<long>(k - 1) * d, node = 1 + p * n + (k - 1);  // the node's index in U
      // entry by entry (a fixed 1 x 1 block into a dynamic one: GCC 12's -Warray-bounds on Eigen's packets)
      for (int i = 0; i < d; ++i) {
        for (int j = 1; j <= n; ++j) S(row + i, static_cast<long>(j - 1) * d + i) += scale * D(k, j);
        for (int c = 0; c < d; ++c) {
          S(row + i, row + c) -= A(i, c);
          rhs(row + i, node * d + c) += B(i, c);
        }
      }
      rhs.middleRows(row, d) -= scale * D(k, 0) * left;
    }
    const Eigen::MatrixXd X = Eigen::PartialPivLU<Eigen::MatrixXd>(S).solve(rhs);
    M.middleRows(d * (1 + p * n), n * d) = X;
    left = X.bottomRows(d);
  }
  return M;
}

}  // namespace detail

// The leading multipliers of the model's monodromy by piecewise Chebyshev collocation (header).
// BadInput: a model that is not linear, several delays, tau != T, or options out of range.
template <class Model>
SpectralResult spectral_multipliers(const Model& model, const SpectralOptions& o = {}) {
  if constexpr (!Model::is_linear) {
    throw BadInput("the spectral reference takes linear models only (the monodromy of a linearisation about an orbit "
                   "needs the orbit's contact times)");
  } else {
    if (o.degree < 2 || o.degree_step < 1 || o.pieces < 1 || o.nev < 1)
      throw BadInput("spectral reference: degree " + std::to_string(o.degree) + " (>= 2), degree_step " +
                     std::to_string(o.degree_step) + " (>= 1), pieces " + std::to_string(o.pieces) + " (>= 1), nev " +
                     std::to_string(o.nev) + " (>= 1)");
    const std::vector<double> taus = delays_of(model);
    const double T = model.period();
    if (taus.size() != 1 || !(std::abs(taus[0] - T) <= 1e-12 * T))
      throw BadInput("the spectral reference needs one delay equal to the period (tau = T); this model has " +
                     std::to_string(taus.size()) + " delay(s), the longest " + format_number(taus.back()) +
                     " against T = " + format_number(T));
    // the switches, each interval cut into `pieces` equal parts
    std::vector<double> cuts{0.0};
    for (double s : time_switches_in_period(model))
      if (s > 1e-12 * T && s < T * (1 - 1e-12)) cuts.push_back(s);
    std::sort(cuts.begin(), cuts.end());
    std::vector<double> starts;
    for (size_t i = 0; i < cuts.size(); ++i) {
      const double a = cuts[i], b = i + 1 < cuts.size() ? cuts[i + 1] : T;
      for (int q = 0; q < o.pieces; ++q) starts.push_back(a + (b - a) * q / o.pieces);
    }
    SpectralResult r;
    r.breakpoints = starts;
    const std::vector<std::complex<double>> coarse =
        dense_eigenvalues(detail::spectral_monodromy(model, starts, T, o.degree), o.backend);
    const Eigen::MatrixXd M = detail::spectral_monodromy(model, starts, T, o.degree + o.degree_step);
    r.dimension = M.rows();
    const std::vector<std::complex<double>> fine = dense_eigenvalues(M, o.backend);
    for (size_t k = 0; k < fine.size() && static_cast<int>(k) < o.nev; ++k) {
      double nearest = INFINITY;
      for (const std::complex<double>& c : coarse) nearest = std::min(nearest, std::abs(c - fine[k]));
      r.multipliers.push_back(fine[k]);
      r.error_estimate.push_back(nearest);
    }
    return r;
  }
}

}  // namespace delayspec
