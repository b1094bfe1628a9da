#pragma once
// Monodromy: the Jacobian of the stroboscopic map, stored as the K step maps of one map and
// applied matrix-free (design.md 1.4). Never forms the n x n matrix except in to_dense().
//
// Layout. x = (u_M, ..., u_0) (oldest block first), n = d (M + 1). Applying the product of K
// step maps writes the blocks into a linear work buffer b[0 .. M + K]: b[0..M] = x, step l
// computes b[M + l + 1] from u_0 = b[M + l] and the delayed slots b[M + l - m - 1 .. M + l - m + 1],
// and the result is b[K .. K + M]. No block is ever shifted or copied during the K steps.
//
// Cost per application: O(K d^2) flops plus O(n + K d) memory traffic. apply_block() runs k
// vectors at once with the k values of each component contiguous, so the inner loop is a
// vectorisable axpy of length k.
//
// Kernels: perform_op and apply_block run the K steps through block_kernel.hpp; blocks of k > 1
// on the path chosen at construction (kernel_dispatch.hpp: AVX2 + FMA for D = 1, 2 where the CPU
// has it, else the portable build; DELAYSPEC_KERNEL=baseline forces the latter). A copy keeps it.
//
// Thread safety: the work buffers are owned by the operator (no allocation per application),
// so one Monodromy must not be applied from two threads at once. Copy it instead.
//
// A LinearOperator (linear_operator.hpp): the eigensolvers take it for any d. The bodies are
// here, so a model of any d instantiates them; d = 1 and 2 are compiled once in the library.
#include <algorithm>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "delayspec/cancellation.hpp"
#include "delayspec/detail/block_kernel.hpp"
#include "delayspec/detail/kernel_dispatch.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/grid.hpp"
#include "delayspec/linear_operator.hpp"
#include "delayspec/step_map.hpp"

namespace delayspec {

template <int D>
class Monodromy final : public LinearOperator {
 public:
  using Scalar = double;

  // maps.size() must equal grid.K (BadInput otherwise).
  Monodromy(const HistoryGrid& grid, std::vector<StepMap<D>> maps);

  Eigen::Index rows() const override { return n_; }
  Eigen::Index cols() const { return n_; }
  const HistoryGrid& grid() const { return grid_; }
  const std::vector<StepMap<D>>& step_maps() const { return maps_; }

  // y = M x. Checks sizes (BadInput naming both) then calls the unchecked kernel.
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  // Y = M X for an n x k block.
  void apply_block(const Eigen::MatrixXd& X, Eigen::MatrixXd& Y) const override;
  // Spectra's interface: y = M x, both of length n, unchecked.
  void perform_op(const double* x, double* y) const override;
  // The dense n x n matrix, by applying the operator to the identity (reference only).
  Eigen::MatrixXd to_dense() const override;

  // Number of single-vector applications so far (a block of k counts k).
  long applications() const override { return applications_; }
  void reset_applications() const { applications_ = 0; }

  // The kernel path this operator runs (kernel_dispatch.hpp).
  KernelPath kernel_path() const { return path_; }

  // An AVX2 path is compiled in the library for these dimensions only.
  static constexpr bool kHasAvx2Kernel = D == 1 || D == 2;

 private:
  void apply_block_raw(const double* X, long ldx, long k, double* Y, long ldy) const;
  // The K steps of one map on the work buffer b of k vectors (k = 1: the plain history), on
  // this operator's kernel path.
  void run_steps(double* b, long k) const;

  HistoryGrid grid_;
  std::vector<StepMap<D>> maps_;
  Eigen::Index n_ = 0;
  mutable std::vector<double> work_;        // (M + 1 + K) d, single vector
  mutable std::vector<double> block_work_;  // (M + 1 + K) d k, interleaved
  mutable long applications_ = 0;
  KernelPath path_ = KernelPath::baseline;
};

template <int D>
Monodromy<D>::Monodromy(const HistoryGrid& grid, std::vector<StepMap<D>> maps)
    : grid_(grid), maps_(std::move(maps)), n_(grid.dimension(D)), path_(choose_kernel_path(kHasAvx2Kernel)) {
  if (static_cast<long>(maps_.size()) != grid_.K)
    throw BadInput("Monodromy: " + std::to_string(maps_.size()) +
                   " step maps given, the grid has K = " + std::to_string(grid_.K) + " steps per map");
  work_.assign(static_cast<size_t>(grid_.M + 1 + grid_.K) * D, 0.0);
}

template <int D>
void Monodromy<D>::perform_op(const double* x, double* y) const {
  throw_if_cancelled();  // one application = one period: the front end may stop here
  const long K = grid_.K;
  double* b = work_.data();
  std::copy(x, x + n_, b);
  run_steps(b, 1);
  std::copy(b + K * D, b + K * D + n_, y);
  ++applications_;
}

template <int D>
void Monodromy<D>::run_steps(double* b, long k) const {
  // b[M+l+1] = P b[M+l] + Q y_tau(t) + R y_tau(t+h), the tap of grid.delay_tap (block_kernel.hpp)
  const long M = grid_.M, K = grid_.K, j0 = grid_.delayed_slot(0);
  const double theta = grid_.theta;
  if (k == 1) {
    single_steps<D>(maps_.data(), K, M, j0, theta, b);  // every path: latency-bound (block_kernel_avx2.cpp)
    return;
  }
  if constexpr (kHasAvx2Kernel) {
    if (path_ == KernelPath::avx2) {
      detail::block_steps_avx2(maps_.data(), K, M, j0, theta, b, k);
      return;
    }
  }
  block_steps<D>(maps_.data(), K, M, j0, theta, b, k);
}

template <int D>
void Monodromy<D>::apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  if (x.size() != n_)
    throw BadInput("Monodromy::apply: x has " + std::to_string(x.size()) + " entries, the operator is " +
                   std::to_string(n_) + " x " + std::to_string(n_));
  y.resize(n_);
  perform_op(x.data(), y.data());
}

template <int D>
void Monodromy<D>::apply_block_raw(const double* X, long ldx, long k, double* Y, long ldy) const {
  // One vector: interleaving is a copy, which perform_op makes with its own (smaller) buffer; the
  // AVX2 transposes would move it element by element (measured slower than the baseline path).
  if (k == 1) {
    perform_op(X, Y);
    return;
  }
  throw_if_cancelled();
  const long M = grid_.M, K = grid_.K;
  const size_t need = static_cast<size_t>(M + 1 + K) * D * k;
  if (block_work_.size() < need) block_work_.resize(need);
  double* b = block_work_.data();
  // b[(j D + r) k + v] = X(j D + r, v); K steps; the result (slots K .. K + M) back into Y
  if constexpr (kHasAvx2Kernel) {
    if (path_ == KernelPath::avx2) {
      detail::transpose_avx2(X, ldx, k, n_, b, k);
      run_steps(b, k);
      detail::transpose_avx2(b + K * D * k, k, n_, k, Y, ldy);
      applications_ += k;
      return;
    }
  }
  interleave(X, ldx, n_, k, b);
  run_steps(b, k);
  deinterleave(b + K * D * k, n_, k, Y, ldy);
  applications_ += k;
}

template <int D>
void Monodromy<D>::apply_block(const Eigen::MatrixXd& X, Eigen::MatrixXd& Y) const {
  if (X.rows() != n_)
    throw BadInput("Monodromy::apply_block: X has " + std::to_string(X.rows()) + " rows, the operator is " +
                   std::to_string(n_) + " x " + std::to_string(n_));
  Y.resize(n_, X.cols());
  if (X.cols() == 0) return;
  apply_block_raw(X.data(), X.rows(), X.cols(), Y.data(), Y.rows());
}

template <int D>
Eigen::MatrixXd Monodromy<D>::to_dense() const {
  Eigen::MatrixXd dense(n_, n_);
  constexpr long kChunk = 32;
  Eigen::MatrixXd I = Eigen::MatrixXd::Zero(n_, kChunk);
  for (long c0 = 0; c0 < n_; c0 += kChunk) {
    const long k = std::min<long>(kChunk, n_ - c0);
    I.setZero();
    for (long v = 0; v < k; ++v) I(c0 + v, v) = 1;
    apply_block_raw(I.data(), n_, k, dense.data() + c0 * n_, n_);
  }
  return dense;
}

// Compiled once in the library (src/monodromy.cpp) for the built-in dimensions.
extern template class Monodromy<1>;
extern template class Monodromy<2>;

}  // namespace delayspec
