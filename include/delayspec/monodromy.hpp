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
// Thread safety: the work buffers are owned by the operator (no allocation per application),
// so one Monodromy must not be applied from two threads at once. Copy it instead.
//
// Usable as a Spectra operator: Scalar, rows(), cols(), perform_op(const double*, double*).
#include <vector>

#include <Eigen/Core>

#include "delayspec/grid.hpp"
#include "delayspec/step_map.hpp"

namespace delayspec {

template <int D>
class Monodromy {
 public:
  using Scalar = double;

  // maps.size() must equal grid.K (BadInput otherwise).
  Monodromy(const HistoryGrid& grid, std::vector<StepMap<D>> maps);

  Eigen::Index rows() const { return n_; }
  Eigen::Index cols() const { return n_; }
  const HistoryGrid& grid() const { return grid_; }
  const std::vector<StepMap<D>>& step_maps() const { return maps_; }

  // y = M x. Checks sizes (BadInput naming both) then calls the unchecked kernel.
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  // Y = M X for an n x k block.
  void apply_block(const Eigen::MatrixXd& X, Eigen::MatrixXd& Y) const;
  // Spectra's interface: y = M x, both of length n, unchecked.
  void perform_op(const double* x, double* y) const;
  // The dense n x n matrix, by applying the operator to the identity (reference only).
  Eigen::MatrixXd to_dense() const;

  // Number of single-vector applications so far (a block of k counts k).
  long applications() const { return applications_; }
  void reset_applications() const { applications_ = 0; }

 private:
  void apply_block_raw(const double* X, long ldx, long k, double* Y, long ldy) const;

  HistoryGrid grid_;
  std::vector<StepMap<D>> maps_;
  Eigen::Index n_ = 0;
  mutable std::vector<double> work_;        // (M + 1 + K) d, single vector
  mutable std::vector<double> block_work_;  // (M + 1 + K) d k, interleaved
  mutable long applications_ = 0;
};

extern template class Monodromy<1>;
extern template class Monodromy<2>;

}  // namespace delayspec
