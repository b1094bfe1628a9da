#pragma once
// Restarted GMRES(m) for A x = b with A given only as a product y = A x (matrix-free): the linear
// solver inside Newton-Krylov shooting (orbit_shooting.hpp), where A = M - I and M is the
// monodromy at the current iterate.
//
// Each cycle builds an orthonormal Krylov basis V_{j+1} of span{r0, A r0, ..., A^j r0} by Arnoldi
// with classical Gram-Schmidt (each pass is two matrix-vector products with the tall basis instead
// of j dot products) and the Daniel-Gragg-Kaufman-Stewart test: a second pass only when the first
// removed more than half of w's squared norm (|w_after| < |w_before| / sqrt(2)): only then can the
// rounding of the first pass, relative to |w_before|, be large against what is left. This is the
// reorthogonalisation rule of ARPACK's Arnoldi step (dnaitr), and it costs one pass instead of two
// when the test passes, which is most steps here (w = M v - v loses little to V). GMRES itself
// asks less of V: with modified Gram-Schmidt and no reorthogonalisation at all it is backward
// stable (Paige, Rozloznik, Strakos 2006). Then the iteration reduces the
// Hessenberg matrix H_j (A V_j = V_{j+1} H_j) to triangular form by Givens rotations, and stops as
// soon as the least-squares residual |beta e1 - H_j y| (= |b - A x_j|_2 in exact arithmetic) is at
// most `tolerance` |b|_2. The true residual is recomputed at every restart and at the end.
//
// Why GMRES converges fast here: the spectrum of a DDE's monodromy accumulates at 0, so A = M - I
// is the identity's negative plus an operator whose eigen/singular values decay (like 1/j for the
// impact model with feedback); GMRES then converges superlinearly, roughly as the product of the
// leading singular values of M. Multipliers near +1 (a fold) make A nearly singular and GMRES slow:
// reported as not converged, never hidden.
//
// Basis vectors are normalised by multiplying with 1 / |w|, not dividing by it: each entry is then
// within 1 ulp of the division's, and an SSE2 division per two entries cost ~2 us per iteration at
// n = 4002, a fifth of one (perf, the orbit search at N = 2000).
//
// Cost per iteration: one application of A plus 4 n j flops per Gram-Schmidt pass (memory bound:
// two reads of the j basis vectors per pass, split between threads at large n). Memory: (m + 1) n
// doubles for the basis, in `basis` when the caller passes one (Newton calls GMRES once per step:
// reusing it spares the page faults of a fresh allocation, measured 1/3 of GMRES at n = 4002).
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "delayspec/detail/gram_schmidt.hpp"

namespace delayspec {

struct GmresOptions {
  double tolerance = 1e-10;  // stop when |b - A x|_2 <= tolerance |b|_2
  int restart = 40;          // basis vectors per cycle (m); clamped to n
  int max_iterations = 400;  // applications of A, over all cycles
};

struct GmresResult {
  Eigen::VectorXd x;             // the approximate solution (from x = 0)
  double relative_residual = 1;  // |b - A x|_2 / |b|_2, recomputed from x
  int iterations = 0;            // applications of A inside Arnoldi
  bool converged = false;        // relative_residual <= tolerance
};

// apply(x, y): y = A x, called as apply(const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::VectorXd& y)
// with x and y of length b.size() (x may be a column of the basis). x starts at 0; b = 0 gives x = 0.
// basis: optional workspace for the Krylov basis, resized to n x (m + 1) (kept between calls).
template <class Apply>
GmresResult gmres(const Apply& apply, const Eigen::VectorXd& b, const GmresOptions& opt,
                  Eigen::MatrixXd* basis = nullptr) {
  const Eigen::Index n = b.size();
  GmresResult res;
  res.x = Eigen::VectorXd::Zero(n);
  const double bnorm = b.norm();
  if (bnorm == 0) {
    res.relative_residual = 0;
    res.converged = true;
    return res;
  }
  const int m = static_cast<int>(std::min<Eigen::Index>(opt.restart, n));
  Eigen::MatrixXd own;
  Eigen::MatrixXd& V = basis ? *basis : own;
  V.resize(n, m + 1);  // a no-op when the workspace already has this shape
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m + 1, m);
  Eigen::VectorXd cs(m), sn(m), g(m + 1), w(n), r = b, h(m + 1), h2(m + 1);
  const int threads = detail::gram_schmidt_threads(n);
  double rnorm = bnorm;
  while (res.iterations < opt.max_iterations) {
    // r = b - A x (true residual at the cycle's start)
    V.col(0) = r * (1 / rnorm);  // a multiply per entry, not a division (header)
    g.setZero();
    g[0] = rnorm;
    int j = 0;
    bool singular = false;
    for (; j < m && res.iterations < opt.max_iterations; ++j) {
      apply(Eigen::Ref<const Eigen::VectorXd>(V.col(j)), w);  // w = A v_j
      ++res.iterations;
      // CGS: h = V^T w; w -= V h; again (h += the second coefficients) when the DGKS test asks
      // for it (header). Each product is one threaded pass over the j + 1 basis vectors
      // (detail/gram_schmidt.hpp).
      const double before = w.squaredNorm();
      detail::basis_coefficients(V.data(), n, j + 1, w.data(), nullptr, h.data(), nullptr, threads);
      detail::ProjectedProducts left =
          detail::subtract_in_basis(V.data(), n, j + 1, h.data(), nullptr, w.data(), nullptr, threads);
      if (!(left.xx >= 0.5 * before)) {  // also when not finite: the second pass shows it
        detail::basis_coefficients(V.data(), n, j + 1, w.data(), nullptr, h2.data(), nullptr, threads);
        left = detail::subtract_in_basis(V.data(), n, j + 1, h2.data(), nullptr, w.data(), nullptr, threads);
        h.head(j + 1) += h2.head(j + 1);
      }
      h[j + 1] = std::sqrt(left.xx);
      // Apply the earlier rotations to the new column, then make one that zeroes h[j + 1].
      for (int i = 0; i < j; ++i) {
        const double t = cs[i] * h[i] + sn[i] * h[i + 1];
        h[i + 1] = -sn[i] * h[i] + cs[i] * h[i + 1];
        h[i] = t;
      }
      const double rho = std::hypot(h[j], h[j + 1]);
      const double hnext = h[j + 1];
      if (rho <= 8 * (j + 2) * std::numeric_limits<double>::epsilon() * std::sqrt(before)) {
        // A v_j lies in A V_j (A is singular on the Krylov space) to within the rounding of the
        // Gram-Schmidt passes and the rotations (a few eps |A v_j| per entry of the column):
        // v_j cannot reduce the residual, the j-step solution is already the least-squares one
        // over V_{j+1}, and the space is invariant, so no later step can either. End with j
        // columns (a pivot at rounding level would only add a noise direction to x).
        singular = true;
        break;
      }
      cs[j] = h[j] / rho, sn[j] = hnext / rho;
      H.col(j).head(j + 1) = h.head(j + 1);
      H(j, j) = rho;
      g[j + 1] = -sn[j] * g[j];
      g[j] = cs[j] * g[j];
      if (hnext > 0) V.col(j + 1) = w * (1 / hnext);
      // |g[j + 1]| is the least-squares residual of the j + 1 step solution.
      if (std::abs(g[j + 1]) <= opt.tolerance * bnorm || hnext == 0) {
        ++j;
        break;
      }
    }
    // x += V_j y with H_j y = g (upper triangular after the rotations)
    if (j > 0) {
      Eigen::VectorXd y = H.topLeftCorner(j, j).triangularView<Eigen::Upper>().solve(g.head(j));
      if (!y.allFinite()) break;  // a zero pivot: the Krylov space holds no better x
      res.x.noalias() += V.leftCols(j) * y;
    }
    apply(Eigen::Ref<const Eigen::VectorXd>(res.x), w);
    r = b - w;
    rnorm = r.norm();
    res.relative_residual = rnorm / bnorm;
    if (res.relative_residual <= opt.tolerance) {
      res.converged = true;
      return res;
    }
    if (singular || !std::isfinite(rnorm)) break;
  }
  res.converged = res.relative_residual <= opt.tolerance;
  return res;
}

}  // namespace delayspec
