#include "delayspec/monodromy.hpp"

#include <algorithm>
#include <string>

#include "delayspec/errors.hpp"

namespace delayspec {

template <int D>
Monodromy<D>::Monodromy(const HistoryGrid& grid, std::vector<StepMap<D>> maps)
    : grid_(grid), maps_(std::move(maps)), n_(grid.dimension(D)) {
  if (static_cast<long>(maps_.size()) != grid_.K)
    throw BadInput("Monodromy: " + std::to_string(maps_.size()) + " step maps given, the grid has K = " +
                   std::to_string(grid_.K) + " steps per map");
  work_.assign(static_cast<size_t>(grid_.M + 1 + grid_.K) * D, 0.0);
}

template <int D>
void Monodromy<D>::perform_op(const double* x, double* y) const {
  using V = Vec<D>;
  const int M = grid_.M, m = grid_.m, K = grid_.K;
  const double theta = grid_.theta, c0 = 1 - theta;
  double* b = work_.data();
  std::copy(x, x + n_, b);
  auto block = [b](long j) { return Eigen::Map<V>(b + j * D); };
  if (theta == 0) {
    // b[M+l+1] = P b[M+l] + Q b[M+l-m] + R b[M+l-m+1]
    for (long l = 0; l < K; ++l) {
      const StepMap<D>& s = maps_[l];
      block(M + l + 1).noalias() = s.P * block(M + l) + s.Q * block(M + l - m) + s.R * block(M + l - m + 1);
    }
  } else {
    // y_tau(t) = c0 b[M+l-m] + theta b[M+l-m-1],  y_tau(t+h) = c0 b[M+l-m+1] + theta b[M+l-m]
    for (long l = 0; l < K; ++l) {
      const StepMap<D>& s = maps_[l];
      const long j = M + l - m;
      V w0 = c0 * block(j) + theta * block(j - 1);
      V w1 = c0 * block(j + 1) + theta * block(j);
      block(M + l + 1).noalias() = s.P * block(M + l) + s.Q * w0 + s.R * w1;
    }
  }
  std::copy(b + static_cast<long>(K) * D, b + static_cast<long>(K) * D + n_, y);
  ++applications_;
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
  const long M = grid_.M, m = grid_.m, K = grid_.K;
  const double theta = grid_.theta, c0 = 1 - theta;
  const size_t need = static_cast<size_t>(M + 1 + K) * D * k;
  if (block_work_.size() < need) block_work_.resize(need);
  double* b = block_work_.data();
  // Interleave: b[(j D + r) k + v] = X(j D + r, v).
  for (long v = 0; v < k; ++v)
    for (long i = 0; i < n_; ++i) b[i * k + v] = X[v * ldx + i];
  const long stride = static_cast<long>(D) * k;  // one history slot
  double w[2 * D * 64];  // delayed values at both ends, for up to 64 vectors per pass
  for (long l = 0; l < K; ++l) {
    const StepMap<D>& s = maps_[l];
    const double* u0 = b + (M + l) * stride;
    const double* d0 = b + (M + l - m) * stride;  // y_tau(t) when aligned
    const double* d1 = d0 + stride;               // y_tau(t + h) when aligned
    double* out = b + (M + l + 1) * stride;
    for (long v0 = 0; v0 < k; v0 += 64) {
      const long kk = std::min<long>(64, k - v0);
      const double* w0 = d0 + v0;
      const double* w1 = d1 + v0;
      long ws = k;  // row stride of w0/w1
      if (theta != 0) {
        const double* dm = d0 - stride;  // u_{m+1}
        for (int r = 0; r < D; ++r)
          for (long v = 0; v < kk; ++v) {
            w[r * 64 + v] = c0 * d0[r * k + v0 + v] + theta * dm[r * k + v0 + v];
            w[(D + r) * 64 + v] = c0 * d1[r * k + v0 + v] + theta * d0[r * k + v0 + v];
          }
        w0 = w;
        w1 = w + D * 64;
        ws = 64;
      }
      // out_r = sum_c P_rc u0_c + Q_rc w0_c + R_rc w1_c, vectorised over the kk vectors
      for (int r = 0; r < D; ++r) {
        double* o = out + r * k + v0;
        for (long v = 0; v < kk; ++v) o[v] = 0;
        for (int c = 0; c < D; ++c) {
          const double p = s.P(r, c), q = s.Q(r, c), rr = s.R(r, c);
          const double* a = u0 + c * k + v0;
          const double* e0 = w0 + c * ws;
          const double* e1 = w1 + c * ws;
          for (long v = 0; v < kk; ++v) o[v] += p * a[v] + q * e0[v] + rr * e1[v];
        }
      }
    }
  }
  const double* res = b + K * stride;
  for (long v = 0; v < k; ++v)
    for (long i = 0; i < n_; ++i) Y[v * ldy + i] = res[i * k + v];
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

template class Monodromy<1>;
template class Monodromy<2>;

}  // namespace delayspec
