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
// on the path chosen at construction (kernel_dispatch.hpp: AVX-512 for D = 2 and AVX2 + FMA for
// D = 1, 2 where the CPU has it, else the portable build; DELAYSPEC_KERNEL forces one). A copy keeps it.
// apply_block with K <= m streams instead of storing the whole linear history
// (apply_block_streaming says why that is exact): for d = 2 and k even straight from X into Y,
// the transposes fused into the steps (kernel_dispatch.hpp: stream_steps_avx512 for k a multiple
// of 8 on the AVX-512 path, else stream_steps_avx2 for k a multiple of 4 on either wide path,
// else stream_steps_portable), otherwise through two small interleaved
// buffers. last_block_layout() tells which ran.
//
// Thread safety: the work buffers are owned by the operator (no allocation per application),
// so one Monodromy must not be applied from two threads at once. Copy it instead.
//
// Several delays (model.hpp): DW = D n rows of delayed values, D x DW blocks Q and R; the steps
// run through block_kernel.hpp's multi_delay_steps on the linear layout, blocks of k > 1 with the
// AVX2 + FMA code and transposes where the shape has them (kernel_dispatch.hpp's kMultiDelayAvx2).
//
// A LinearOperator (linear_operator.hpp): the eigensolvers take it for any d. The bodies are
// here, so a model of any d instantiates them; d = 1 and 2 are compiled once in the library.
#include <algorithm>
#include <functional>
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

template <int D, int DW = D>
class Monodromy final : public LinearOperator {
 public:
  using Scalar = double;

  // maps.size() must equal grid.K (BadInput otherwise).
  Monodromy(const HistoryGrid& grid, std::vector<StepMap<D, DW>> maps);

  Eigen::Index rows() const override { return n_; }
  Eigen::Index cols() const { return n_; }
  const HistoryGrid& grid() const { return grid_; }
  const std::vector<StepMap<D, DW>>& step_maps() const { return maps_; }
  // Hands the step maps back (the operator is empty afterwards): a caller that evaluates the map
  // again, as Newton does, refills the same storage instead of allocating and faulting it in anew.
  std::vector<StepMap<D, DW>> take_step_maps() && { return std::move(maps_); }

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

  // The widest path compiled in the library for D: the AVX-512 kernel is d = 2's streaming one,
  // AVX2 + FMA code exists for D = 1, 2 and their shapes with 2-4 delays; another shape (compiled
  // outside the library) is portable.
  static constexpr KernelPath kWidestPath = DW != D   ? (detail::kMultiDelayAvx2<D, DW> ? KernelPath::avx2
                                                                                   : KernelPath::baseline)
                                            : D == 2 ? KernelPath::avx512
                                            : D == 1 ? KernelPath::avx2
                                                     : KernelPath::baseline;
  static constexpr bool kHasAvx2Kernel = kWidestPath != KernelPath::baseline;

  // How the last apply_block ran (the tests assert it): one vector through perform_op; the whole
  // interleaved history (linear); two L1 staging buffers (streaming); streaming with the
  // transposes fused into the steps, no staging, for d = 2: AVX-512 for k a multiple of 8
  // (fused_avx512, AVX-512 path), AVX2 + FMA for k a multiple of 4 (fused_avx2, either wide path),
  // else the portable build for k even (fused_portable, on any path).
  enum class BlockLayout { none, single, linear, streaming, fused_avx512, fused_avx2, fused_portable };
  BlockLayout last_block_layout() const { return last_layout_; }

 private:
  void apply_block_raw(const double* X, long ldx, long k, double* Y, long ldy) const;
  // apply_block_raw for k > 1 when no computed slot is read back as a delayed one (K <= m), and
  // otherwise (the whole interleaved history in block_work_).
  void apply_block_streaming(const double* X, long ldx, long k, double* Y, long ldy) const;
  void apply_block_linear(const double* X, long ldx, long k, double* Y, long ldy) const;
  // On this operator's kernel path: steps l0 .. l0 + count - 1 on k > 1 interleaved vectors
  // (block_steps' u, delayed); rows of X interleaved into slots and back (interleave, deinterleave).
  void run_block_steps(long l0, long count, double* u, const double* delayed, long k) const;
  void to_slots(const double* X, long ldx, long rows, long k, double* b) const;
  void from_slots(const double* b, long rows, long k, double* Y, long ldy) const;

  HistoryGrid grid_;
  std::vector<StepMap<D, DW>> maps_;
  Eigen::Index n_ = 0;
  mutable std::vector<double> work_;        // (M + 1 + K) d, single vector
  mutable std::vector<double> block_work_;  // (M + 1 + K) d k, interleaved
  mutable long applications_ = 0;
  mutable BlockLayout last_layout_ = BlockLayout::none;
  KernelPath path_ = KernelPath::baseline;
};

template <int D, int DW>
Monodromy<D, DW>::Monodromy(const HistoryGrid& grid, std::vector<StepMap<D, DW>> maps)
    : grid_(grid), maps_(std::move(maps)), n_(grid.dimension(D)), path_(choose_kernel_path(kWidestPath)) {
  if (static_cast<long>(maps_.size()) != grid_.K)
    throw BadInput("Monodromy: " + std::to_string(maps_.size()) +
                   " step maps given, the grid has K = " + std::to_string(grid_.K) + " steps per map");
  work_.assign(static_cast<size_t>(grid_.M + 1 + grid_.K) * D, 0.0);
}

template <int D, int DW>
void Monodromy<D, DW>::perform_op(const double* x, double* y) const {
  throw_if_cancelled();  // one application = one period: the front end may stop here
  const long M = grid_.M, K = grid_.K;
  double* b = work_.data();
  std::copy(x, x + n_, b);
  // b[M+l+1] = P b[M+l] + Q y_tau(t) + R y_tau(t+h), the tap of grid.delay_tap (block_kernel.hpp).
  // Portable code on every path: latency-bound (block_kernel_avx2.cpp).
  if constexpr (DW != D) multi_delay_steps<D, DW>(maps_.data(), K, M, grid_.delays, b, 1);
  else single_steps<D>(maps_.data(), K, M, grid_.delayed_slot(0), grid_.theta, b);
  std::copy(b + K * D, b + K * D + n_, y);
  ++applications_;
}

template <int D, int DW>
void Monodromy<D, DW>::run_block_steps(long l0, long count, double* u, const double* delayed, long k) const {
  if constexpr (kHasAvx2Kernel && DW == D) {
    if (runs_avx2_code(path_)) {
      detail::block_steps_avx2(maps_.data() + l0, count, u, delayed, grid_.theta, k);
      return;
    }
  }
  block_steps<D>(maps_.data() + l0, count, u, delayed, grid_.theta, k);
}

template <int D, int DW>
void Monodromy<D, DW>::to_slots(const double* X, long ldx, long rows, long k, double* b) const {
  if constexpr (kHasAvx2Kernel) {
    if (runs_avx2_code(path_)) {
      detail::transpose_avx2(X, ldx, k, rows, b, k);
      return;
    }
  }
  interleave(X, ldx, rows, k, b);
}

template <int D, int DW>
void Monodromy<D, DW>::from_slots(const double* b, long rows, long k, double* Y, long ldy) const {
  if constexpr (kHasAvx2Kernel) {
    if (runs_avx2_code(path_)) {
      detail::transpose_avx2(b, k, rows, k, Y, ldy);
      return;
    }
  }
  deinterleave(b, rows, k, Y, ldy);
}

template <int D, int DW>
void Monodromy<D, DW>::apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  if (x.size() != n_)
    throw BadInput("Monodromy::apply: x has " + std::to_string(x.size()) + " entries, the operator is " +
                   std::to_string(n_) + " x " + std::to_string(n_));
  y.resize(n_);
  perform_op(x.data(), y.data());
}

template <int D, int DW>
void Monodromy<D, DW>::apply_block_raw(const double* X, long ldx, long k, double* Y, long ldy) const {
  // One vector: interleaving is a copy, which perform_op makes with its own (smaller) buffer; the
  // AVX2 transposes would move it element by element (measured slower than the baseline path).
  if (k == 1) {
    perform_op(X, Y);
    last_layout_ = BlockLayout::single;
    return;
  }
  throw_if_cancelled();
  // Step l reads the slots j0 + l - 1 .. j0 + l + 1 (j0 + l - 1 only when theta != 0). When the
  // last of them, j0 + K, is still one of x's slots (<= M, i.e. K <= m: the delay is at least
  // one map long), no computed slot is ever read back, and every computed slot M + 1 .. M + K is
  // part of the result (K <= M + 1): the history need not be stored.
  // Streaming writes Y while it still reads X: only when they do not overlap (apply_block(X, X)
  // takes the linear layout, which reads all of X first).
  if constexpr (DW != D) {  // several delays: the linear layout
    apply_block_linear(X, ldx, k, Y, ldy);
  } else {
    const long first_read = grid_.delayed_slot(0) - (grid_.theta == 0 ? 0 : 1);
    const bool disjoint =
        std::less<>()(X + (k - 1) * ldx + n_ - 1, Y) || std::less<>()(Y + (k - 1) * ldy + n_ - 1, X);
    if (disjoint && first_read >= 0 && grid_.delayed_slot(0) + grid_.K <= grid_.M)
      apply_block_streaming(X, ldx, k, Y, ldy);
    else apply_block_linear(X, ldx, k, Y, ldy);
  }
  applications_ += k;
}

template <int D, int DW>
void Monodromy<D, DW>::apply_block_linear(const double* X, long ldx, long k, double* Y, long ldy) const {
  last_layout_ = BlockLayout::linear;
  const long M = grid_.M, K = grid_.K, stride = D * k;
  const size_t need = static_cast<size_t>(M + 1 + K) * stride;
  if (block_work_.size() < need) block_work_.resize(need);
  double* b = block_work_.data();
  // b[(j D + r) k + v] = X(j D + r, v); K steps; the result (slots K .. K + M) back into Y
  to_slots(X, ldx, n_, k, b);
  if constexpr (DW != D) {
    if constexpr (kHasAvx2Kernel) {
      if (runs_avx2_code(path_)) detail::multi_delay_steps_avx2(maps_.data(), K, M, grid_.delays, b, k);
      else multi_delay_steps<D, DW>(maps_.data(), K, M, grid_.delays, b, k);
    } else {
      multi_delay_steps<D, DW>(maps_.data(), K, M, grid_.delays, b, k);
    }
  } else {
    run_block_steps(0, K, b + M * stride, b + grid_.delayed_slot(0) * stride, k);
  }
  from_slots(b + K * stride, n_, k, Y, ldy);
}

template <int D, int DW>
void Monodromy<D, DW>::apply_block_streaming(const double* X, long ldx, long k, double* Y, long ldy) const {
  // d = 2, k even: the fused kernels read X and write Y themselves (no buffer, no copies;
  // AVX2 4 vectors at a time, portable 2; bench_apply, docs/benchmarks.md: per vector 1.6-2.7x
  // faster than the staged loop below on AVX2 for k = 8..32, 1.05-1.8x portable). Otherwise:
  // Chunks of C steps: interleave the x slots the chunk reads into `in`, step into `out` (slot 0
  // = u0, the previous chunk's last slot), de-interleave out's new slots straight into Y. Both
  // buffers stay in L1 (~16 KiB each), so X is read once and Y written once, against the linear
  // path's whole interleaved history (x in, all K new slots, the result out: 2-4x the bytes,
  // from L2 or L3; bench_apply, docs/benchmarks.md). The copies are the same transposes.
  const long M = grid_.M, K = grid_.K, stride = D * k, j0 = grid_.delayed_slot(0);
  // The result's first slots K .. M are x's slots (none when K = M + 1): a plain copy per column.
  const auto copy_x_slots = [&] {
    for (long v = 0; v < k; ++v) std::copy(X + v * ldx + K * D, X + v * ldx + n_, Y + v * ldy);
  };
  if constexpr (D == 2) {
    if (path_ == KernelPath::avx512 && k % 8 == 0) {
      detail::stream_steps_avx512(maps_.data(), K, M, j0, grid_.theta, X, ldx, k, Y, ldy);
      copy_x_slots();
      last_layout_ = BlockLayout::fused_avx512;
      return;
    }
    if (runs_avx2_code(path_) && k % 4 == 0) {
      detail::stream_steps_avx2(maps_.data(), K, M, j0, grid_.theta, X, ldx, k, Y, ldy);
      copy_x_slots();
      last_layout_ = BlockLayout::fused_avx2;
      return;
    }
    if (k % 2 == 0) {
      detail::stream_steps_portable(maps_.data(), K, M, j0, grid_.theta, X, ldx, k, Y, ldy);
      copy_x_slots();
      last_layout_ = BlockLayout::fused_portable;
      return;
    }
  }
  last_layout_ = BlockLayout::streaming;
  const long back = grid_.theta == 0 ? 0 : 1;  // slot j - 1 is read only when theta != 0
  const long C = std::max<long>(8, 1024 / stride);
  const size_t need = static_cast<size_t>(2 * C + 3) * stride;
  if (block_work_.size() < need) block_work_.resize(need);
  double* in = block_work_.data();      // C + 2 slots: j0 + l0 - back .. j0 + l0 + C
  double* out = in + (C + 2) * stride;  // C + 1 slots: M + l0 .. M + l0 + C
  to_slots(X + M * D, ldx, D, k, out);  // u0 of step 0: x's slot M
  for (long l0 = 0; l0 < K; l0 += C) {
    const long steps = std::min(C, K - l0);
    const long lo = j0 + l0 - back, hi = j0 + l0 + steps;  // the slots these steps read
    to_slots(X + lo * D, ldx, (hi - lo + 1) * D, k, in);
    run_block_steps(l0, steps, out, in + back * stride, k);
    from_slots(out + stride, steps * D, k, Y + (M + l0 + 1 - K) * D, ldy);  // slot s is Y's slot s - K
    std::copy(out + steps * stride, out + (steps + 1) * stride, out);       // the next chunk's u0
  }
  copy_x_slots();
}

template <int D, int DW>
void Monodromy<D, DW>::apply_block(const Eigen::MatrixXd& X, Eigen::MatrixXd& Y) const {
  if (X.rows() != n_)
    throw BadInput("Monodromy::apply_block: X has " + std::to_string(X.rows()) + " rows, the operator is " +
                   std::to_string(n_) + " x " + std::to_string(n_));
  Y.resize(n_, X.cols());
  if (X.cols() == 0) return;
  apply_block_raw(X.data(), X.rows(), X.cols(), Y.data(), Y.rows());
}

template <int D, int DW>
Eigen::MatrixXd Monodromy<D, DW>::to_dense() const {
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

// Compiled once in the library (src/engine/monodromy.cpp) for the built-in dimensions.
extern template class Monodromy<1>;
extern template class Monodromy<2>;

}  // namespace delayspec
