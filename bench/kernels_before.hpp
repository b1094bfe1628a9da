#pragma once
// The step-map kernels as they were on main at 2863684 (before issue 17, item 5), kept so that
// bench_apply measures before and after in one run: Monodromy::perform_op's per-step Eigen
// expression, and apply_block's step_block with D read-modify-write passes per output row and
// the interpolated taps staged in a buffer. Benchmark-only; the library does not use them.
#include <algorithm>
#include <vector>

#include "delayspec/monodromy.hpp"

namespace delayspec::before {

template <int D>
void step_block_before(const StepMap<D>& s, const double* u0, const double* d0, long k, double theta, double* out) {
  constexpr long kChunk = 64;
  const long stride = static_cast<long>(D) * k;
  const double c0 = 1 - theta;
  const double* d1 = d0 + stride;
  double w[2 * D * kChunk];
  for (long v0 = 0; v0 < k; v0 += kChunk) {
    const long kk = std::min<long>(kChunk, k - v0);
    const double* w0 = d0 + v0;
    const double* w1 = d1 + v0;
    long ws = k;
    if (theta != 0) {
      const double* dm = d0 - stride;
      for (int r = 0; r < D; ++r)
        for (long v = 0; v < kk; ++v) {
          w[r * kChunk + v] = c0 * d0[r * k + v0 + v] + theta * dm[r * k + v0 + v];
          w[(D + r) * kChunk + v] = c0 * d1[r * k + v0 + v] + theta * d0[r * k + v0 + v];
        }
      w0 = w;
      w1 = w + D * kChunk;
      ws = kChunk;
    }
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

// apply_block: interleave, K steps, de-interleave (X, Y column-major n x k).
template <int D>
void apply_block(const Monodromy<D>& op, const double* X, long k, double* Y, std::vector<double>& work) {
  const HistoryGrid& g = op.grid();
  const long M = g.M, K = g.K, n = op.rows();
  work.resize(static_cast<size_t>(M + 1 + K) * D * k);
  double* b = work.data();
  for (long v = 0; v < k; ++v)
    for (long i = 0; i < n; ++i) b[i * k + v] = X[v * n + i];
  const long stride = static_cast<long>(D) * k;
  for (long l = 0; l < K; ++l)
    step_block_before<D>(op.step_maps()[l], b + (M + l) * stride, b + g.delayed_slot(l) * stride, k, g.theta,
                         b + (M + l + 1) * stride);
  const double* res = b + K * stride;
  for (long v = 0; v < k; ++v)
    for (long i = 0; i < n; ++i) Y[v * n + i] = res[i * k + v];
}

// perform_op: y = M x, one vector.
template <int D>
void perform_op(const Monodromy<D>& op, const double* x, double* y, std::vector<double>& work) {
  using V = Vec<D>;
  const HistoryGrid& g = op.grid();
  const long M = g.M, m = g.m, K = g.K, n = op.rows();
  work.resize(static_cast<size_t>(M + 1 + K) * D);
  double* b = work.data();
  std::copy(x, x + n, b);
  auto block = [b](long j) { return Eigen::Map<V>(b + j * D); };
  const auto& maps = op.step_maps();
  if (g.theta == 0) {
    for (long l = 0; l < K; ++l) {
      const StepMap<D>& s = maps[l];
      block(M + l + 1).noalias() = s.P * block(M + l) + s.Q * block(M + l - m) + s.R * block(M + l - m + 1);
    }
  } else {
    for (long l = 0; l < K; ++l) {
      const StepMap<D>& s = maps[l];
      const DelayTap<V> tap = g.delay_tap<V>(l, block);
      block(M + l + 1).noalias() = s.P * block(M + l) + s.Q * tap.w0 + s.R * tap.w1;
    }
  }
  std::copy(b + K * D, b + K * D + n, y);
}

}  // namespace delayspec::before
