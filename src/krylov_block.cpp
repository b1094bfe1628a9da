// Block Krylov-Schur backend of floquet_multipliers() (solver = block): the operator applied to b
// vectors at once (Monodromy::apply_block), the basis orthogonalised with BLAS-3.
//
// Relation kept throughout (V orthonormal, p multiplied columns, the last b columns not yet):
//     M V(:, 0:p) = V(:, 0:p + b) H(0:p + b, 0:p).
// Expansion: W = M V(:, p:p+b); block classical Gram-Schmidt twice against V(:, 0:p+b) (two dgemm
// each: c = V^T W, W -= V c), then the block itself orthonormalised by Cholesky QR twice (two more
// passes over W); H gets c and the triangular factor. When a new direction is numerically absent
// (|R_ii| <= 1e-12 |M v_i|: the Krylov space is invariant in it, e.g. a rank-deficient or strongly
// unstable monodromy whose other multipliers are below round-off) the block is orthonormalised
// column by column and that column replaced by a random vector orthogonal to the basis, with a
// zero coefficient: the relation holds to rounding and the search goes on in a fresh direction.
// Rayleigh-Ritz: Ritz values theta of H_p = H(0:p, 0:p), Ritz vectors V y, residual estimates
// |H(p:p+b, 0:p) y| (|y| = 1); a pair has converged when estimate <= tol max(|theta|, eps^(2/3)),
// the criterion Spectra and ARPACK use. Restart (Krylov-Schur, Stewart 2001): the real Schur form
// of H_p with the k largest-modulus values first (LAPACK dgees with a selection), V <- V Z_k,
// H_k <- T_k, the coupling row block <- H(p:p+b, 0:p) Z_k; the last block stays the not yet
// multiplied one. k = (nev + m) / 2 keeps the wanted values and a margin.
//
// Cost per expansion: one apply_block of b vectors plus 8 n p b flops of dgemm (compute bound, not
// the memory-bound dgemv of one vector at a time); per restart 2 n p k flops.
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "delayspec/errors.hpp"
#include "delayspec/floquet.hpp"
#include "krylov.hpp"

extern "C" {
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c,
            const int* ldc);
void dgees_(const char* jobvs, const char* sort, int (*select)(const double*, const double*), const int* n, double* a,
            const int* lda, int* sdim, double* wr, double* wi, double* vs, const int* ldvs, double* work,
            const int* lwork, int* bwork, int* info);
}

namespace delayspec::krylov {

namespace {

// C = alpha op(A) op(B) + beta C (column-major, BLAS dgemm).
void gemm(char ta, char tb, long m, long n, long k, double alpha, const double* A, long lda, const double* B, long ldb,
          double beta, double* C, long ldc) {
  const int im = static_cast<int>(m), in = static_cast<int>(n), ik = static_cast<int>(k);
  const int ilda = static_cast<int>(lda), ildb = static_cast<int>(ldb), ildc = static_cast<int>(ldc);
  dgemm_(&ta, &tb, &im, &in, &ik, &alpha, A, &ilda, B, &ildb, &beta, C, &ildc);
}

// dgees' selection: |lambda| >= threshold (the wanted, largest-modulus values).
thread_local double select_threshold = 0;
int select_large(const double* re, const double* im) { return std::hypot(*re, *im) >= select_threshold ? 1 : 0; }

class BlockKrylovSchur {
 public:
  BlockKrylovSchur(long n, int b, int m) : n_(n), b_(b), m_(m), V_(n, m + b), H_(Eigen::MatrixXd::Zero(m + b, m)) {}

  // Orthonormalises W (n x b) against V(:, 0:j) and within itself: W_in = V(:, 0:j) c + W R.
  void orthonormalise(long j, Eigen::MatrixXd& W, Eigen::MatrixXd& c, Eigen::MatrixXd& R) {
    const Eigen::VectorXd norm_in = W.colwise().norm().transpose();
    c = Eigen::MatrixXd::Zero(j, b_);
    if (j > 0) {
      Eigen::MatrixXd pass(j, b_);
      for (int twice = 0; twice < 2; ++twice) {                                             // CGS2
        gemm('T', 'N', j, b_, n_, 1.0, V_.data(), n_, W.data(), n_, 0.0, pass.data(), j);   // pass = V^T W
        gemm('N', 'N', n_, b_, j, -1.0, V_.data(), n_, pass.data(), j, 1.0, W.data(), n_);  // W -= V pass
        c += pass;
      }
    }
    if (!cholesky_qr2(W, R, norm_in)) column_qr(j, W, R, norm_in);
  }

  // W = Q R by Cholesky QR twice; false when a column is (nearly) dependent: then nothing changed.
  bool cholesky_qr2(Eigen::MatrixXd& W, Eigen::MatrixXd& R, const Eigen::VectorXd& norm_in) {
    Eigen::MatrixXd Q = W;
    R = Eigen::MatrixXd::Identity(b_, b_);
    for (int twice = 0; twice < 2; ++twice) {
      Eigen::MatrixXd G(b_, b_);
      gemm('T', 'N', b_, b_, n_, 1.0, Q.data(), n_, Q.data(), n_, 0.0, G.data(), b_);  // G = Q^T Q
      Eigen::LLT<Eigen::MatrixXd> llt(G);
      if (llt.info() != Eigen::Success) return false;
      const Eigen::MatrixXd Ri = llt.matrixU();
      const Eigen::VectorXd d = Ri.diagonal();
      // a direction lost to rounding, or too ill-conditioned for Cholesky QR (cond > 1e6)
      if (twice == 0) {
        for (int i = 0; i < b_; ++i)
          if (!(d[i] > 1e-12 * norm_in[i])) return false;
        if (d.minCoeff() < 1e-6 * d.maxCoeff()) return false;
      }
      Ri.triangularView<Eigen::Upper>().solveInPlace<Eigen::OnTheRight>(Q);  // Q <- Q Ri^{-1}
      R = Ri * R;
    }
    W = std::move(Q);
    return true;
  }

  // Gram-Schmidt column by column (twice), a lost direction replaced by a random one (R_ii = 0).
  void column_qr(long j, Eigen::MatrixXd& W, Eigen::MatrixXd& R, const Eigen::VectorXd& norm_in) {
    R = Eigen::MatrixXd::Zero(b_, b_);
    for (int i = 0; i < b_; ++i) {
      Eigen::VectorXd w = W.col(i);
      for (int twice = 0; twice < 2; ++twice) {
        const Eigen::VectorXd r = W.leftCols(i).transpose() * w;
        w.noalias() -= W.leftCols(i) * r;
        R.col(i).head(i) += r;
      }
      const double rho = w.norm();
      if (rho > 1e-12 * norm_in[i]) {
        W.col(i) = w / rho;
        R(i, i) = rho;
        continue;
      }
      w = start_vector(n_, 0x5eedULL + seed_++);
      for (int twice = 0; twice < 2; ++twice) {
        if (j > 0) w -= V_.leftCols(j) * (V_.leftCols(j).transpose() * w).eval();
        w -= W.leftCols(i) * (W.leftCols(i).transpose() * w).eval();
      }
      W.col(i) = w.normalized();
    }
  }

  long n_;
  int b_, m_;
  Eigen::MatrixXd V_, H_;
  std::uint64_t seed_ = 0;
};

}  // namespace

RitzPairs block_ritz_pairs(const LinearOperator& op, const Settings& s, const Eigen::VectorXd& start) {
  const long n = op.rows();
  const int nev = s.nev;
  // Block size at most a third of the room above nev; basis m >= nev + 2 b + 2 so that a restart
  // keeping (nev + m) / 2 values (one more for a split pair) leaves room for a block.
  const int b = static_cast<int>(std::max<long>(1, std::min<long>(s.block_size, (n - nev) / 3)));
  const int m = static_cast<int>(std::min<long>(std::max(s.ncv, nev + 2 * b + 2), n - b));
  const int keep = std::max(nev, std::min((nev + m) / 2, m - b - 1));
  BlockKrylovSchur k(n, b, m);
  Eigen::MatrixXd& V = k.V_;
  Eigen::MatrixXd& H = k.H_;

  // Start block: the common start vector and b - 1 more from the same generator.
  Eigen::MatrixXd W(n, b), c, R, X, Y;
  W.col(0) = start;
  for (int i = 1; i < b; ++i) W.col(i) = start_vector(n, 0xb10cULL + static_cast<std::uint64_t>(i));
  k.orthonormalise(0, W, c, R);
  V.leftCols(b) = W;
  long j = b;  // basis columns; the last b not yet multiplied

  RitzPairs pairs;
  const double eps23 = std::pow(std::numeric_limits<double>::epsilon(), 2.0 / 3.0);
  for (int iteration = 1;; ++iteration) {
    // Expand while a whole block fits: M V(:, j-b:j) -> new block.
    while (j + b <= m + b) {
      X = V.middleCols(j - b, b);
      op.apply_block(X, Y);
      k.orthonormalise(j, Y, c, R);
      H.block(0, j - b, j, b) = c;
      H.block(j, j - b, b, b) = R;
      V.middleCols(j, b) = Y;
      j += b;
    }
    const long p = j - b;  // Rayleigh quotient size
    const Eigen::MatrixXd Hp = H.topLeftCorner(p, p);
    const Eigen::MatrixXd coupling = H.block(p, 0, b, p);
    Eigen::EigenSolver<Eigen::MatrixXd> es(Hp);
    if (es.info() != Eigen::Success)
      throw NumericalFailure("Krylov (block): the eigenvalues of the " + std::to_string(p) + " x " + std::to_string(p) +
                             " Rayleigh quotient did not converge");
    const Eigen::VectorXcd theta = es.eigenvalues();
    const Eigen::MatrixXcd Yc = es.eigenvectors();  // unit columns
    std::vector<long> order(p);
    for (long i = 0; i < p; ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](long a, long c2) { return std::abs(theta[a]) > std::abs(theta[c2]); });
    // A pair split by nev counts whole.
    int wanted = nev;
    if (wanted < p && theta[order[wanted - 1]].imag() != 0 &&
        theta[order[wanted]] == std::conj(theta[order[wanted - 1]]))
      ++wanted;
    std::vector<std::complex<double>> values;
    std::vector<double> estimates;
    int converged = 0;
    bool all = true;
    for (int i = 0; i < wanted; ++i) {
      const long col = order[i];
      const double est = (coupling.cast<std::complex<double>>() * Yc.col(col)).norm();
      values.push_back(theta[col]);
      estimates.push_back(est);
      const bool ok = est <= s.tolerance * std::max(std::abs(theta[col]), eps23);
      converged += ok;
      all = all && ok;
    }
    if (all) {
      std::vector<std::complex<double>> wanted_theta;
      std::vector<Eigen::VectorXcd> wanted_y;
      for (int i = 0; i < wanted; ++i) {
        wanted_theta.push_back(theta[order[i]]);
        wanted_y.push_back(Yc.col(order[i]));
      }
      pairs = ritz_pairs_in_basis(wanted_theta, wanted_y, V.leftCols(p));
      pairs.converged = converged;
      pairs.iterations = iteration;
      return pairs;
    }
    if (iteration >= s.max_iterations)
      throw NumericalFailure(
          "Krylov (block) did not converge: " + std::to_string(converged) + " of nev = " + std::to_string(nev) +
          " Ritz values converged after " + std::to_string(iteration) +
          " iterations (max_iterations = " + std::to_string(s.max_iterations) + " = 1 + max_restarts, basis " +
          std::to_string(m) + ", block " + std::to_string(b) + "), largest relative residual estimate " +
          format_number(largest_relative_estimate(values, estimates, nev)) + " > tol " + short_number(s.tolerance));

    // Restart: ordered real Schur form, the `keep` largest moduli first. dgees selects by modulus;
    // ties (exact zeros of a rank-deficient monodromy, round-off-level values of a strongly
    // unstable one) can select more than fit: then a larger threshold, down to nev values.
    Eigen::MatrixXd T, Z(p, p);
    const int ip = static_cast<int>(p);
    int sdim = 0, info = 0;
    Eigen::VectorXd wr(p), wi(p);
    std::vector<int> bwork(p);
    std::vector<double> work;
    bool restarted = false;
    for (int q = keep - 1; q >= nev - 1 && !restarted; --q) {
      select_threshold = std::abs(theta[order[q]]) * (1 - 1e-12);
      if (!(select_threshold > 0)) continue;
      T = Hp;
      int lwork = -1;
      double query = 0;
      dgees_("V", "S", select_large, &ip, T.data(), &ip, &sdim, wr.data(), wi.data(), Z.data(), &ip, &query, &lwork,
             bwork.data(), &info);
      lwork = static_cast<int>(query);
      work.assign(static_cast<size_t>(std::max(1, lwork)), 0.0);
      dgees_("V", "S", select_large, &ip, T.data(), &ip, &sdim, wr.data(), wi.data(), Z.data(), &ip, work.data(),
             &lwork, bwork.data(), &info);
      restarted = info == 0 && sdim >= nev && sdim + b <= m;
    }
    if (!restarted)
      throw NumericalFailure("Krylov (block): no restart keeps between nev = " + std::to_string(nev) + " and " +
                             std::to_string(m - b) + " Ritz values (dgees info " + std::to_string(info) + ", " +
                             std::to_string(sdim) + " selected); try another solver");
    Eigen::MatrixXd kept(n, sdim);
    gemm('N', 'N', n, sdim, p, 1.0, V.data(), n, Z.data(), p, 0.0, kept.data(), n);  // V Z_k
    const Eigen::MatrixXd residual_block = V.middleCols(p, b);
    V.leftCols(sdim) = kept;
    V.middleCols(sdim, b) = residual_block;
    H.setZero();
    H.topLeftCorner(sdim, sdim) = T.topLeftCorner(sdim, sdim);
    H.block(sdim, 0, b, sdim) = coupling * Z.leftCols(sdim);
    j = sdim + b;
  }
}

}  // namespace delayspec::krylov
