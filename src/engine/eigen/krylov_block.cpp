// Krylov-Schur backend of floquet_multipliers() (solver = block, block_size = b vectors per
// product). b = 1 (the default, auto's choice at large n): one vector per product and classical
// Gram-Schmidt with delayed reorthogonalisation (expand_single), two passes over the basis per
// product in threaded row chunks (detail/gram_schmidt.hpp). b > 1: the operator applied to b vectors at
// once (Monodromy::apply_block), the basis orthogonalised with BLAS-3.
//
// Relation kept throughout (V orthonormal, p multiplied columns, the last b columns not yet):
//     M V(:, 0:p) = V(:, 0:p + b) H(0:p + b, 0:p).
// Expansion (b > 1): W = M V(:, p:p+b); block classical Gram-Schmidt twice against V(:, 0:p+b) (two
// dgemm each: c = V^T W, W -= V c), then the block itself orthonormalised by Cholesky QR twice (two
// more passes over W); H gets c and the triangular factor. When a new direction is numerically
// absent (|R_ii| <= 1e-12 |M v_i|: the Krylov space is invariant in it, e.g. a rank-deficient or
// strongly unstable monodromy whose other multipliers are below round-off) the block is
// orthonormalised column by column and that column replaced by a random vector orthogonal to the
// basis, with a zero coefficient: the relation holds to rounding and the search goes on in a fresh
// direction (expand_single does the same for its one vector).
// Rayleigh-Ritz: Ritz values theta of H_p = H(0:p, 0:p), Ritz vectors V y, residual estimates
// |H(p:p+b, 0:p) y| (|y| = 1); a pair has converged when estimate <= tol max(|theta|, eps^(2/3)),
// the criterion Spectra and ARPACK use. Restart (Krylov-Schur, Stewart 2001): the real Schur form
// of H_p with the k largest-modulus values first (LAPACK dgees with a selection), V <- V Z_k (in
// place, by row chunks), H_k <- T_k, the coupling row block <- H(p:p+b, 0:p) Z_k; the last block
// stays the not yet multiplied one. k = (nev + m) / 2 keeps the wanted values and a margin.
//
// Cost per product at large n, where reading the n x m basis is what costs (an application of the
// monodromy at N = 10^6 takes ~2 ms, one read of a 41-column basis ~20 ms): b = 1 reads the j
// basis columns twice (CGS2 as ARPACK does it: four times); b > 1 makes 8 n p b flops of dgemm
// per expansion of b vectors but needs 1.7-5x the products for the same accuracy
// (docs/benchmarks.md). Per restart 2 n p k flops.
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "delayspec/detail/gram_schmidt.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/floquet.hpp"
#include "engine/linalg/blas.hpp"
#include "engine/eigen/krylov.hpp"
#include "engine/linalg/linear_algebra.hpp"

namespace delayspec::krylov {

using detail::basis_coefficients;
using detail::gram_schmidt_threads;
using detail::ProjectedProducts;
using detail::subtract_in_basis;

namespace {

// dgees' selection: |lambda| >= threshold (the wanted, largest-modulus values).
thread_local double select_threshold = 0;
int select_large(const double* re, const double* im) { return std::hypot(*re, *im) >= select_threshold ? 1 : 0; }

// The Rayleigh quotient's eigenvalues and unit right eigenvectors, by LAPACK dgeev through the
// loaded table. Not Eigen's EigenSolver: its instantiation took 11 s of this unit's 21 s of
// compile, on the program's path to its first number (docs/benchmarks.md, "Build time").
struct Eigenpairs {
  Eigen::VectorXcd values;
  Eigen::MatrixXcd vectors;  // unit columns
};

Eigenpairs rayleigh_quotient_eigenpairs(Eigen::MatrixXd h) {
  const int n = static_cast<int>(h.rows()), one = 1;
  Eigen::VectorXd wr(n), wi(n);
  Eigen::MatrixXd vr(n, n);
  double query = 0, unused = 0;
  int lwork = -1, info = 0;
  const auto dgeev = detail::lapack().dgeev;
  dgeev("N", "V", &n, h.data(), &n, wr.data(), wi.data(), &unused, &one, vr.data(), &n, &query, &lwork, &info);
  lwork = std::max(1, static_cast<int>(query));
  std::vector<double> work(static_cast<size_t>(lwork));
  dgeev("N", "V", &n, h.data(), &n, wr.data(), wi.data(), &unused, &one, vr.data(), &n, work.data(), &lwork, &info);
  if (info != 0)
    throw NumericalFailure("Krylov (block): the eigenvalues of the " + std::to_string(n) + " x " + std::to_string(n) +
                           " Rayleigh quotient did not converge (LAPACK dgeev info = " + std::to_string(info) + ")");
  Eigenpairs e{Eigen::VectorXcd(n), Eigen::MatrixXcd::Zero(n, n)};
  for (int j = 0; j < n; ++j) {
    e.values[j] = {wr[j], wi[j]};
    if (wi[j] == 0) {
      e.vectors.col(j) = vr.col(j).cast<std::complex<double>>();
    } else if (wi[j] > 0 && j + 1 < n) {  // a conjugate pair: columns j and j + 1 hold Re and Im
      e.vectors.col(j).real() = vr.col(j), e.vectors.col(j).imag() = vr.col(j + 1);
      e.vectors.col(j + 1) = e.vectors.col(j).conjugate();
      e.values[j + 1] = {wr[j + 1], wi[j + 1]};
      ++j;
    }
  }
  return e;
}

// The Krylov-Schur factorisation M V(:, 0:p) = V(:, 0:p + b) H(0:p + b, 0:p) of one operator, and
// what grows it (expand), reads it (rayleigh_ritz, ritz_pairs) and shrinks it (restart): the basis,
// the projection and the last Rayleigh quotient's eigenpairs are this object's, no caller reaches
// into them (Spectra's KrylovSchur / ARPACK's reverse communication keep theirs so too).
class BlockKrylovSchur {
 public:
  // The wanted values of the last Rayleigh-Ritz step, largest modulus first (a pair split by nev
  // counted whole), with their residual estimates.
  struct RitzStep {
    std::vector<std::complex<double>> values;
    std::vector<double> estimates;
    int converged = 0;  // of them, those whose estimate <= tol max(|theta|, eps^(2/3))
    bool all_converged() const { return converged == static_cast<int>(values.size()); }
  };

  // A basis of m + b columns for an operator of dimension n, b vectors per product.
  BlockKrylovSchur(const LinearOperator& op, int b, int m)
      : op_(op), n_(op.rows()), b_(b), m_(m), V_(n_, m + b), H_(Eigen::MatrixXd::Zero(m + b, m)) {}

  // The first block: `start` and b - 1 more vectors from the same generator, orthonormalised.
  void start(const Eigen::VectorXd& start) {
    Eigen::MatrixXd W(n_, b_), c, R;
    W.col(0) = start;
    for (int i = 1; i < b_; ++i) W.col(i) = start_vector(n_, 0xb10cULL + static_cast<std::uint64_t>(i));
    orthonormalise(0, W, c, R);
    V_.leftCols(b_) = W;
    j_ = b_;
  }

  // Expands while a whole block fits: M V(:, j-b:j) -> a new block, until m columns are multiplied.
  void expand() {
    if (b_ == 1) expand_single(j_, m_);
    Eigen::MatrixXd X, Y, c, R;
    while (j_ + b_ <= m_ + b_) {
      X = V_.middleCols(j_ - b_, b_);
      op_.apply_block(X, Y);
      orthonormalise(j_, Y, c, R);
      H_.block(0, j_ - b_, j_, b_) = c;
      H_.block(j_, j_ - b_, b_, b_) = R;
      V_.middleCols(j_, b_) = Y;
      j_ += b_;
    }
  }

  // Rayleigh-Ritz on H_p = H(0:p, 0:p): its eigenpairs (kept for ritz_pairs and restart) and the
  // residual estimates |H(p:p+b, 0:p) y| (|y| = 1) of the nev largest in modulus.
  RitzStep rayleigh_ritz(int nev, double tolerance) {
    p_ = j_ - b_;
    Hp_ = H_.topLeftCorner(p_, p_);
    coupling_ = H_.block(p_, 0, b_, p_);
    ritz_ = rayleigh_quotient_eigenpairs(Hp_);
    const Eigen::VectorXcd& theta = ritz_.values;
    const Eigen::MatrixXcd& Yc = ritz_.vectors;  // unit columns
    order_.resize(p_);
    for (long i = 0; i < p_; ++i) order_[i] = i;
    std::stable_sort(order_.begin(), order_.end(),
                     [&](long a, long c2) { return std::abs(theta[a]) > std::abs(theta[c2]); });
    // A pair split by nev counts whole.
    int wanted = nev;
    if (wanted < p_ && theta[order_[wanted - 1]].imag() != 0 &&
        theta[order_[wanted]] == std::conj(theta[order_[wanted - 1]]))
      ++wanted;
    const double eps23 = std::pow(std::numeric_limits<double>::epsilon(), 2.0 / 3.0);
    RitzStep step;
    for (int i = 0; i < wanted; ++i) {
      const long col = order_[i];
      const double est = (coupling_.cast<std::complex<double>>() * Yc.col(col)).norm();
      step.values.push_back(theta[col]);
      step.estimates.push_back(est);
      step.converged += est <= tolerance * std::max(std::abs(theta[col]), eps23);
    }
    return step;
  }

  // The pairs of the last Rayleigh-Ritz step's wanted values, vectors in the basis.
  RitzPairs ritz_pairs(const RitzStep& step) const {
    std::vector<std::complex<double>> wanted_theta;
    std::vector<Eigen::VectorXcd> wanted_y;
    for (size_t i = 0; i < step.values.size(); ++i) {
      wanted_theta.push_back(ritz_.values[order_[i]]);
      wanted_y.push_back(ritz_.vectors.col(order_[i]));
    }
    return ritz_pairs_in_basis(wanted_theta, wanted_y, V_.leftCols(p_));
  }

  // Restart (Krylov-Schur, Stewart 2001) after a Rayleigh-Ritz step: ordered real Schur form of
  // H_p with the `keep` largest moduli first (dgees selects by modulus; ties, the exact zeros of a
  // rank-deficient monodromy or round-off-level values of a strongly unstable one, can select more
  // than fit: then a larger threshold, down to nev values), V(:, 0:k) <- V Z_k, H_k <- T_k, the
  // coupling row block <- H(p:p+b, 0:p) Z_k; the last block stays the one not yet multiplied.
  void restart(int nev, int keep) {
    const long p = p_;
    const Eigen::VectorXcd& theta = ritz_.values;
    Eigen::MatrixXd T, Z(p, p);
    const int ip = static_cast<int>(p);
    int sdim = 0, info = 0;
    Eigen::VectorXd wr(p), wi(p);
    std::vector<int> bwork(p);
    std::vector<double> work;
    const auto dgees = detail::lapack().dgees;
    bool restarted = false;
    for (int q = keep - 1; q >= nev - 1 && !restarted; --q) {
      select_threshold = std::abs(theta[order_[q]]) * (1 - 1e-12);
      if (!(select_threshold > 0)) continue;
      T = Hp_;
      int lwork = -1;
      double query = 0;
      dgees("V", "S", select_large, &ip, T.data(), &ip, &sdim, wr.data(), wi.data(), Z.data(), &ip, &query, &lwork,
            bwork.data(), &info);
      lwork = static_cast<int>(query);
      work.assign(static_cast<size_t>(std::max(1, lwork)), 0.0);
      dgees("V", "S", select_large, &ip, T.data(), &ip, &sdim, wr.data(), wi.data(), Z.data(), &ip, work.data(), &lwork,
            bwork.data(), &info);
      restarted = info == 0 && sdim >= nev && sdim + b_ <= m_;
    }
    if (!restarted)
      throw NumericalFailure("Krylov (block): no restart keeps between nev = " + std::to_string(nev) + " and " +
                             std::to_string(m_ - b_) + " Ritz values (dgees info " + std::to_string(info) + ", " +
                             std::to_string(sdim) + " selected); try another solver");
    rotate_basis(p, Z, sdim);                      // V(:, 0:sdim) <- V Z_k
    V_.middleCols(sdim, b_) = V_.middleCols(p, b_);  // disjoint: sdim + b <= m = p
    H_.setZero();
    H_.topLeftCorner(sdim, sdim) = T.topLeftCorner(sdim, sdim);
    H_.block(sdim, 0, b_, sdim) = coupling_ * Z.leftCols(sdim);
    source_norm_ = 1;
    j_ = sdim + b_;
  }

 private:
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

  // Expansion with one vector per product (b = 1): Arnoldi with classical Gram-Schmidt and delayed
  // reorthogonalisation (DCGS2; Bielich, Langou, Thomas, Swirydowicz, Yamazaki, Boman 2022), two
  // reads of the basis per product where CGS2 takes four. On entry columns 0..j-1 exist; Q =
  // V(:, 0:j-1) is orthonormal, u = V(:, j-1) has been projected against Q once (not twice, not
  // normalised) and enters the relation through its row, M Q = Q H(0:j-1, 0:j-1) + u H(j-1, 0:j-1).
  // One step, with w = M u:
  //   pass 1 (reads Q):  s = Q^T u,  t = Q^T w
  //   pass 2 (reads Q):  u <- u - Q s,  w <- w - Q t;  r = |u|, q = u / r, g = q^T w
  // u = Q s + r q turns the relation into M Q = [Q q] H' with H(0:j-1, :) += s row, H(j-1, :) = r row,
  // and M q = (M u - M Q s) / r = (w_in - [Q q] H' s) / r, whose coefficients on [Q q] are
  // c = ([t; g] - H' s) / r and whose remainder z = (w - q g) / r (w projected once) is the next u.
  // Rounding: s = O(eps) |u| after the first projection, so the delayed second one corrects H' by
  // O(eps) and c loses O(eps |s| / r) <= O(eps) |M| as long as r > 1e-12 |M q_prev| (below that the
  // direction is lost and replaced, as in column_qr).
  void expand_single(long& j, long m) {
    Eigen::VectorXd w(n_), s, t, hs;
    while (j <= m) {
      const long q_cols = j - 1;
      double* u = V_.col(j - 1).data();
      op_.perform_op(u, w.data());
      s.resize(q_cols);
      t.resize(q_cols);
      basis_coefficients(V_.data(), n_, q_cols, u, w.data(), s.data(), t.data(), threads_);
      const ProjectedProducts p = subtract_in_basis(V_.data(), n_, q_cols, s.data(), t.data(), u, w.data(), threads_);
      // A non-finite product would pass for a lost direction below: say what it is, at once.
      if (!std::isfinite(p.xx + p.yy))
        throw NumericalFailure("Krylov (block): the operator returned a non-finite vector (product " +
                               std::to_string(j) + " of the basis)");
      const double r = std::sqrt(p.xx);
      const Eigen::RowVectorXd row = H_.row(j - 1).head(q_cols);
      H_.topLeftCorner(q_cols, q_cols) += s * row;
      if (!(r > 1e-12 * source_norm_)) {  // u was rounding noise: M's space is invariant so far
        H_.row(j - 1).head(q_cols).setZero();
        replace_lost_column(j - 1);
        continue;
      }
      H_.row(j - 1).head(q_cols) = r * row;
      const double g = p.xy / r;
      hs = H_.topLeftCorner(j, q_cols) * s;
      Eigen::VectorXd c(j);
      c.head(q_cols) = t - hs.head(q_cols);
      c[q_cols] = g - hs[q_cols];
      c /= r;
      H_.col(j - 1).head(j) = c;
      detail::divide_and_split(n_, r, g, V_.col(j - 1).data(), w.data(), V_.col(j).data(), threads_);
      H_.row(j).head(j).setZero();
      H_(j, j - 1) = 1;
      // |M q|^2 = |c|^2 + |z|^2, |z|^2 = (|w|^2 - g^2) / r^2
      source_norm_ = std::sqrt(c.squaredNorm() + std::max(0.0, p.yy - g * g) / (r * r));
      ++j;
    }
    finish_single(m);
  }

  // The last column V(:, m) gets its second projection and is normalised: the relation
  // M V(:, 0:m) = V(:, 0:m + 1) H(0:m + 1, 0:m) with V orthonormal, as the block expansion leaves it.
  void finish_single(long m) {
    double* u = V_.col(m).data();
    Eigen::VectorXd s(m);
    basis_coefficients(V_.data(), n_, m, u, nullptr, s.data(), nullptr, threads_);
    const ProjectedProducts p = subtract_in_basis(V_.data(), n_, m, s.data(), nullptr, u, nullptr, threads_);
    const double r = std::sqrt(p.xx);
    const Eigen::RowVectorXd row = H_.row(m).head(m);
    H_.topLeftCorner(m, m) += s * row;
    if (!(r > 1e-12 * source_norm_)) {  // invariant subspace: no coupling, any orthonormal successor
      H_.row(m).head(m).setZero();
      replace_lost_column(m);
      return;
    }
    H_.row(m).head(m) = r * row;
    V_.col(m) /= r;
  }

  // V(:, i) <- a random unit vector orthogonal to V(:, 0:i) (CGS2); the caller zeroes its row.
  void replace_lost_column(long i) {
    V_.col(i) = start_vector(n_, 0x5eedULL + seed_++);
    Eigen::VectorXd s(i);
    for (int twice = 0; twice < 2; ++twice) {
      basis_coefficients(V_.data(), n_, i, V_.col(i).data(), nullptr, s.data(), nullptr, threads_);
      subtract_in_basis(V_.data(), n_, i, s.data(), nullptr, V_.col(i).data(), nullptr, threads_);
    }
    V_.col(i).normalize();
    source_norm_ = 1;
  }

  // V(:, 0:k) <- V(:, 0:p) Z in place, a chunk of rows at a time: no second n x k matrix.
  void rotate_basis(long p, const Eigen::MatrixXd& Z, long k) {
    constexpr long kRows = 4096;
    Eigen::MatrixXd rows(kRows, k);
    for (long a = 0; a < n_; a += kRows) {
      const long h = std::min(kRows, n_ - a);
      gemm('N', 'N', h, k, p, 1.0, V_.data() + a, n_, Z.data(), p, 0.0, rows.data(), kRows);
      V_.block(a, 0, h, k) = rows.topRows(h);
    }
  }

  const LinearOperator& op_;
  long n_;
  int b_, m_;
  Eigen::MatrixXd V_, H_;
  long j_ = 0;  // basis columns; the last b not yet multiplied
  // The last Rayleigh-Ritz step: its size p, H_p, the coupling rows H(p:p+b, 0:p), the eigenpairs
  // and their order by modulus.
  long p_ = 0;
  Eigen::MatrixXd Hp_, coupling_;
  Eigenpairs ritz_;
  std::vector<long> order_;
  std::uint64_t seed_ = 0;
  int threads_ = gram_schmidt_threads(n_);
  double source_norm_ = 1;  // |M q| of the vector the current u was projected from (|start| at first)
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
  BlockKrylovSchur krylov(op, b, m);
  krylov.start(start);
  for (int iteration = 1;; ++iteration) {
    krylov.expand();
    const BlockKrylovSchur::RitzStep step = krylov.rayleigh_ritz(nev, s.tolerance);
    if (step.all_converged()) {
      RitzPairs pairs = krylov.ritz_pairs(step);
      pairs.converged = step.converged;
      pairs.iterations = iteration;
      return pairs;
    }
    if (iteration >= s.max_iterations)
      throw NumericalFailure(
          "Krylov (block) did not converge: " + std::to_string(step.converged) + " of nev = " + std::to_string(nev) +
          " Ritz values converged after " + std::to_string(iteration) +
          " iterations (max_iterations = " + std::to_string(s.max_iterations) + " = 1 + max_restarts, basis " +
          std::to_string(m) + ", block " + std::to_string(b) + "), largest relative residual estimate " +
          format_number(largest_relative_estimate(step.values, step.estimates, nev)) + " > tol " +
          format_number(s.tolerance, 3));
    krylov.restart(nev, keep);
  }
}

}  // namespace delayspec::krylov
