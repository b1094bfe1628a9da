#pragma once
// The one kernel that applies a step map to k tangent vectors at once (design.md 1.3-1.4),
// shared by Monodromy::apply_block (stored step maps) and the Lyapunov propagation (step maps
// used as soon as the stepper produces them).
//
// Layout: a history slot holds D components of k vectors, component-major with the k values
// of a component contiguous ("interleaved"): slot[r * k + v] = component r of vector v. A slot
// is D k doubles. With the delayed slot j = (current slot) - m (HistoryGrid::delayed_slot), the
// step computes HistoryGrid::delay_tap's formula (grid.hpp) on k vectors at once:
//
//   out = P u0 + Q w0 + R w1,   w0 = (1 - theta) b[j] + theta b[j - 1],
//                               w1 = (1 - theta) b[j + 1] + theta b[j]
//
// (theta = 0: w0 = b[j], w1 = b[j + 1]). Cost per step: 3 D^2 k FMAs, reads 3-4 slots, writes
// one; the inner loop is an axpy of length k and vectorises. No allocation, no checks.
#include <algorithm>

#include "delayspec/step_map.hpp"

namespace delayspec {

// u0: the current slot; d0: the delayed slot j (its neighbours j - 1 and j + 1 are d0 -+ D k);
// out: the new slot (must not alias the inputs).
template <int D>
inline void step_block(const StepMap<D>& s, const double* u0, const double* d0, long k, double theta, double* out) {
  constexpr long kChunk = 64;  // vectors per pass when the delayed values need interpolating
  const long stride = static_cast<long>(D) * k;
  const double c0 = 1 - theta;
  const double* d1 = d0 + stride;
  double w[2 * D * kChunk];
  for (long v0 = 0; v0 < k; v0 += kChunk) {
    const long kk = std::min<long>(kChunk, k - v0);
    const double* w0 = d0 + v0;
    const double* w1 = d1 + v0;
    long ws = k;  // row stride of w0/w1
    if (theta != 0) {
      const double* dm = d0 - stride;  // b[j - 1]
      for (int r = 0; r < D; ++r)
        for (long v = 0; v < kk; ++v) {
          w[r * kChunk + v] = c0 * d0[r * k + v0 + v] + theta * dm[r * k + v0 + v];
          w[(D + r) * kChunk + v] = c0 * d1[r * k + v0 + v] + theta * d0[r * k + v0 + v];
        }
      w0 = w;
      w1 = w + D * kChunk;
      ws = kChunk;
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

}  // namespace delayspec
