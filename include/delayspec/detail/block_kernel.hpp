#pragma once
// The kernels that apply step maps to tangent vectors (design.md 1.3-1.4): step_block (one step,
// k vectors) shared by Monodromy::apply_block and the Lyapunov propagation; block_steps (the K
// steps of one map, k vectors) and single_steps (the K steps, one vector: perform_op).
//
// Math. With the delayed slot j = (current slot) - m (HistoryGrid::delayed_slot), one step is
// HistoryGrid::delay_tap's formula (grid.hpp):
//
//   out = P u0 + Q w0 + R w1,   w0 = (1 - theta) b[j] + theta b[j - 1],
//                               w1 = (1 - theta) b[j + 1] + theta b[j]
//
// (theta = 0: w0 = b[j], w1 = b[j + 1]; b[j - 1] is then not read: it may not exist).
//
// Layout of k vectors: a history slot holds D components of k vectors, component-major with
// the k values of a component contiguous ("interleaved"): slot[r * k + v] = component r of
// vector v. A slot is D k doubles. One vector (k = 1) is the plain history, slot j at b + j D.
//
// Cost per step per vector: 3 D^2 FMAs (plus 2 D for the interpolation), reads the current and
// 2-3 delayed slots, writes one. step_block makes ONE pass over the k vectors with D
// accumulators held in registers (the loop over v vectorises; the P, Q, R coefficients are
// loop-invariant scalars). single_steps keeps u0 in registers across steps: one vector is a
// recurrence (u0 of step l + 1 is the output of step l), so its speed is the latency of
// P u0 + (Q w0 + R w1), with the delayed part computed off that critical path.
//
// Target: an instantiation tag. The portable kernels use PortableTarget; a translation unit
// compiled for another instruction set (src/engine/kernels/block_kernel_avx2.cpp) instantiates the same
// templates with its own tag of internal linkage, so the two machine codes get distinct
// symbols and the linker can never merge one into the other (kernel_dispatch.hpp).
// No allocation, no checks: the callers check sizes.
#include <type_traits>

#include "delayspec/grid.hpp"
#include "delayspec/step_map.hpp"

namespace delayspec {

namespace detail {
struct PortableTarget {};
}  // namespace detail

// u0: the current slot; d0: the delayed slot j (its neighbours j - 1 and j + 1 are d0 -+ D k);
// out: the new slot (must not alias the inputs). KC > 0: k is the compile-time constant KC (the
// Lyapunov loop's few tangent vectors: the loops over v unroll into straight-line code; with a
// runtime k = 2 the loop overhead measured ~2 ns per step); KC = 0: k as given.
template <int D, class Target = detail::PortableTarget, int KC = 0>
inline void step_block(const StepMap<D>& s, const double* u0, const double* d0, long k_runtime, double theta,
                       double* __restrict out) {
  const long k = KC > 0 ? KC : k_runtime;
  const long stride = static_cast<long>(D) * k;
  const double* d1 = d0 + stride;  // b[j + 1]
  // s.P, s.Q, s.R: loop-invariant (out is __restrict), broadcast once per step
  // The sum: one term per statement, so that with FMA each term is one FMA (`acc += a b + c d`
  // is a multiply, an FMA and an add; starting from acc = 0 adds one more add), and ordered
  // delayed part first, P u0 last: u0 is the previous step's out, so the steps form a recurrence
  // and the chain from u0 to out is only the last D FMAs; the Q, R part of the next step, which
  // does not depend on u0, overlaps it.
  if (theta == 0) {
    // out_r = sum_c Q_rc b[j]_c + R_rc b[j+1]_c + sum_c P_rc u0_c, one pass over the k vectors
    for (long v = 0; v < k; ++v)
      for (int r = 0; r < D; ++r) {
        double acc = s.Q.coeff(r, 0) * d0[v];
        acc += s.R.coeff(r, 0) * d1[v];
        for (int c = 1; c < D; ++c) {
          acc += s.Q.coeff(r, c) * d0[c * k + v];
          acc += s.R.coeff(r, c) * d1[c * k + v];
        }
        for (int c = 0; c < D; ++c) acc += s.P.coeff(r, c) * u0[c * k + v];
        out[r * k + v] = acc;
      }
    return;
  }
  const double c0 = 1 - theta;
  const double* dm = d0 - stride;  // b[j - 1]
  for (long v = 0; v < k; ++v) {
    double w0[D], w1[D];
    for (int c = 0; c < D; ++c) {
      w0[c] = c0 * d0[c * k + v] + theta * dm[c * k + v];
      w1[c] = c0 * d1[c * k + v] + theta * d0[c * k + v];
    }
    for (int r = 0; r < D; ++r) {
      double acc = s.Q.coeff(r, 0) * w0[0];  // the same order as above
      acc += s.R.coeff(r, 0) * w1[0];
      for (int c = 1; c < D; ++c) {
        acc += s.Q.coeff(r, c) * w0[c];
        acc += s.R.coeff(r, c) * w1[c];
      }
      for (int c = 0; c < D; ++c) acc += s.P.coeff(r, c) * u0[c * k + v];
      out[r * k + v] = acc;
    }
  }
}

// One step's derivative, factored (a StepLinearisation from TrapezoidStepper::step), applied to
// k interleaved tangent vectors without forming P, Q, R (detail/sub_step_derivative.hpp):
//
//   out = S^{-1} [ L u0 + Bl w0 + Br w1 ],   w0, w1 as in step_block.
//
// A slot of c vectors is a D x c row-major matrix (slot[r * k + v]); with KC > 0 the k = KC
// vectors are one fixed-size block and SubStepDerivative::apply's row operations run packed over
// the vectors (two per SSE2 register), with KC = 0 they go one at a time. 4 D^2 multiply-adds per vector against
// step_block's 3 D^2 plus forming P, Q, R (3 D^3 per step): at D = 2, k = 2, 32 against 48.
// A step that was split (events, time switches) has its map formed: step_block.
template <int D, int KC>
[[gnu::always_inline]] inline void apply_factored_step(const detail::SubStepDerivative<D>& s, const double* u0,
                                                       const double* d0, long k_runtime, double theta,
                                                       double* __restrict out) {
  constexpr int C = KC > 0 ? KC : 1;  // vectors per block
  using Slot = Eigen::Matrix<double, D, C, C == 1 ? Eigen::ColMajor : Eigen::RowMajor>;
  // KC > 0: a slot is one contiguous D x KC row-major block; KC = 0: vector v is the column
  // slot[v], slot[k + v], ... (inner stride k)
  using Stride = std::conditional_t<KC == 0, Eigen::InnerStride<Eigen::Dynamic>, Eigen::InnerStride<1>>;
  using In = Eigen::Map<const Slot, Eigen::Unaligned, Stride>;
  using Out = Eigen::Map<Slot, Eigen::Unaligned, Stride>;
  const long k = KC > 0 ? KC : k_runtime;
  const long stride = static_cast<long>(D) * k;
  const Stride layout(KC == 0 ? k : 1);
  auto slot = [&](const double* p, long v) { return In(p + v, D, C, layout); };
  for (long v = 0; v < k; v += C) {
    if (theta == 0) {
      Out(out + v, D, C, layout) = s.apply(slot(u0, v), slot(d0, v), slot(d0 + stride, v));
    } else {
      const double c0 = 1 - theta;
      const Slot w0 = c0 * slot(d0, v) + theta * slot(d0 - stride, v);
      const Slot w1 = c0 * slot(d0 + stride, v) + theta * slot(d0, v);
      Out(out + v, D, C, layout) = s.apply(slot(u0, v), w0, w1);
    }
  }
}

// A step's linearisation, factored or formed, applied to k interleaved vectors (the Lyapunov
// loop): the arguments as in step_block.
template <int D, int KC>
[[gnu::always_inline]] inline void apply_step_linearisation(const StepLinearisation<D>& s, const double* u0,
                                                            const double* d0, long k, double theta,
                                                            double* __restrict out) {
  if (s.factored) apply_factored_step<D, KC>(s.sub, u0, d0, k, theta, out);
  else step_block<D, detail::PortableTarget, KC>(s.map, u0, d0, k, theta, out);
}

// Interleave an n x k column-major block X (leading dimension ldx) into slots: b[i k + v] = X(i, v),
// and back. Row tiles of about 16 KiB of b stay in L1 while the k columns pass over them (a
// column-by-column pass over all n rows would evict each line of b k times).
inline long interleave_tile_rows(long k) { return k >= 256 ? 8 : 2048 / k; }

// dst[c ldd + r] = src[r lds + c] for r < rows, c < cols, in 2 x 2 blocks: two rows of two
// adjacent columns are two 16-byte loads and two unpacks into two 16-byte stores (GCC's SLP
// vectoriser forms them from the four scalar moves; element by element the copy is one scalar
// store per double). Column tiles as in interleave_tile_rows.
inline void transpose_portable(const double* src, long lds, long rows, long cols, double* __restrict dst, long ldd) {
  const long tile = interleave_tile_rows(rows);
  const long rows2 = rows & ~1L;
  for (long c0 = 0; c0 < cols; c0 += tile) {
    const long c1 = c0 + tile < cols ? c0 + tile : cols;
    const long c12 = c0 + ((c1 - c0) & ~1L);
    for (long r = 0; r < rows2; r += 2) {
      const double* s0 = src + r * lds;
      const double* s1 = s0 + lds;
      for (long c = c0; c < c12; c += 2) {
        const double a0 = s0[c], a1 = s0[c + 1], b0 = s1[c], b1 = s1[c + 1];
        dst[c * ldd + r] = a0;
        dst[c * ldd + r + 1] = b0;
        dst[(c + 1) * ldd + r] = a1;
        dst[(c + 1) * ldd + r + 1] = b1;
      }
      for (long c = c12; c < c1; ++c) dst[c * ldd + r] = s0[c], dst[c * ldd + r + 1] = s1[c];
    }
    for (long r = rows2; r < rows; ++r)
      for (long c = c0; c < c1; ++c) dst[c * ldd + r] = src[r * lds + c];
  }
}

inline void interleave(const double* X, long ldx, long n, long k, double* __restrict b) {
  transpose_portable(X, ldx, k, n, b, k);
}

inline void deinterleave(const double* b, long n, long k, double* __restrict Y, long ldy) {
  transpose_portable(b, k, n, k, Y, ldy);
}

// The K steps of one map on k interleaved vectors: step l reads u0 = u[l] and the delayed slots
// around delayed[l] (slots of D k doubles; delayed[l - 1 .. l + 1] when theta != 0) and writes
// u[l + 1]. On one linear history b (Monodromy's layout) u = b[M] and delayed = b[j0]
// (HistoryGrid::delayed_slot(l) = j0 + l); the streaming apply_block passes two staging buffers.
// KC as in step_block.
template <int D, class Target, int KC>
inline void block_steps_k(const StepMap<D>* maps, long K, double* u, const double* delayed, double theta, long k) {
  const long stride = static_cast<long>(D) * (KC > 0 ? KC : k);
  // theta == 0 tested once, not per step: with the literal 0 the inlined step has no branch, and
  // the compiler broadcasts the 3 D^2 coefficients straight from memory (a load each) instead
  // of loading them as scalars above the branch and broadcasting in registers (a shuffle each).
  if (theta == 0)
    for (long l = 0; l < K; ++l)
      step_block<D, Target, KC>(maps[l], u + l * stride, delayed + l * stride, k, 0.0, u + (l + 1) * stride);
  else
    for (long l = 0; l < K; ++l)
      step_block<D, Target, KC>(maps[l], u + l * stride, delayed + l * stride, k, theta, u + (l + 1) * stride);
}

// The block sizes the solvers use (block_size 2, 4, 8; to_dense's chunks of 32; 16) run with k
// a compile-time constant: the step's loops over v become straight-line vector code. With a
// runtime k the loop set-up for a trip count of 2-8 vectors cost more than the step's FMAs
// (bench_apply, docs/benchmarks.md). Any other k runs the generic loop.
template <int D, class Target = detail::PortableTarget>
inline void block_steps(const StepMap<D>* maps, long K, double* u, const double* delayed, double theta, long k) {
  switch (k) {
    case 2: return block_steps_k<D, Target, 2>(maps, K, u, delayed, theta, k);
    case 4: return block_steps_k<D, Target, 4>(maps, K, u, delayed, theta, k);
    case 8: return block_steps_k<D, Target, 8>(maps, K, u, delayed, theta, k);
    case 16: return block_steps_k<D, Target, 16>(maps, K, u, delayed, theta, k);
    case 32: return block_steps_k<D, Target, 32>(maps, K, u, delayed, theta, k);
    default: return block_steps_k<D, Target, 0>(maps, K, u, delayed, theta, k);
  }
}

// The same K steps on one vector (slot j at b + j D), u0 carried in registers.
template <int D>
inline void single_steps(const StepMap<D>* maps, long K, long M, long first_delayed, double theta, double* b) {
  const double c0 = 1 - theta;
  double u[D];
  for (int c = 0; c < D; ++c) u[c] = b[M * D + c];
  for (long l = 0; l < K; ++l) {
    const StepMap<D>& s = maps[l];
    const double* d0 = b + (first_delayed + l) * D;
    double w0[D], w1[D];
    for (int c = 0; c < D; ++c) {
      w0[c] = theta == 0 ? d0[c] : c0 * d0[c] + theta * d0[c - D];
      w1[c] = theta == 0 ? d0[D + c] : c0 * d0[D + c] + theta * d0[c];
    }
    double out[D];
    for (int r = 0; r < D; ++r) {
      double acc = 0;  // Q w0 + R w1: independent of u, off the critical path
      for (int c = 0; c < D; ++c) acc += s.Q.coeff(r, c) * w0[c] + s.R.coeff(r, c) * w1[c];
      for (int c = 0; c < D; ++c) acc += s.P.coeff(r, c) * u[c];  // the recurrence: D dependent FMAs
      out[r] = acc;
    }
    double* next = b + (M + l + 1) * D;
    for (int r = 0; r < D; ++r) next[r] = u[r] = out[r];
  }
}

// Several delays (model.hpp, grid.hpp's delay_taps). Step l of k interleaved vectors on one
// linear history b (slot j at b + j D k, u0 in slot `current` = M + l):
//
//   out = P u0 + sum_i Q_i w0_i + R_i w1_i,   w0_i = (1 - theta_i) b[j_i] + theta_i b[j_i - 1],
//                                             w1_i = (1 - theta_i) b[j_i + 1] + theta_i b[j_i],
//
// j_i = current - m_i, Q_i and R_i the D x D column blocks of delay i. The same single pass over
// the k vectors as step_block, D accumulators per vector, the delayed part first and P u0 last;
// the interpolation is done for every delay (theta_i = 0 multiplies a valid slot by 0), so the
// loop over the vectors has no branch and vectorises. NT = DW / D delays, KC and Target as in
// step_block (the AVX2 + FMA instantiations: src/engine/kernels/block_kernel_avx2.cpp).
template <int NT>
struct DelayPlaces {
  long m[NT];
  double theta[NT];
  // From the grid's delays (none with one delay: then unused, left 0).
  explicit DelayPlaces(const std::vector<HistoryGrid::DelayPosition>& delays) : m{}, theta{} {
    for (size_t i = 0; i < NT && i < delays.size(); ++i) m[i] = delays[i].m, theta[i] = delays[i].theta;
  }
};

template <int D, int DW, int KC = 0, class Target = detail::PortableTarget>
inline void multi_delay_block(const Mat<D>& P, const RectMat<D, DW>& Q, const RectMat<D, DW>& R, const double* b,
                              long current, const DelayPlaces<DW / D>& places, long k_runtime,
                              double* __restrict out) {
  constexpr int NT = DW / D;
  const long k = KC > 0 ? KC : k_runtime;
  const long stride = static_cast<long>(D) * k;
  const double* u0 = b + current * stride;
  const double *d0[NT], *dm[NT], *d1[NT];
  double c0[NT], th[NT];
  for (int i = 0; i < NT; ++i) {
    d0[i] = b + (current - places.m[i]) * stride;
    d1[i] = d0[i] + stride;
    th[i] = places.theta[i];
    c0[i] = 1 - th[i];
    dm[i] = th[i] == 0 ? d0[i] : d0[i] - stride;  // slot j - 1 only when it is read with a weight
  }
  if (k == 1) {  // one vector: a recurrence through u0, so the delayed part first, P u0 last
    double acc[D] = {};
    for (int i = 0; i < NT; ++i)
      for (int c = 0; c < D; ++c) {
        const double w0 = c0[i] * d0[i][c] + th[i] * dm[i][c], w1 = c0[i] * d1[i][c] + th[i] * d0[i][c];
        for (int r = 0; r < D; ++r) acc[r] += Q.coeff(r, i * D + c) * w0 + R.coeff(r, i * D + c) * w1;
      }
    for (int r = 0; r < D; ++r) {
      for (int c = 0; c < D; ++c) acc[r] += P.coeff(r, c) * u0[c];
      out[r] = acc[r];
    }
    return;
  }
  // k vectors: one pass, D accumulators per vector (step_block's loop; vectorises over v)
  for (long v = 0; v < k; ++v) {
    double acc[D] = {};
    for (int i = 0; i < NT; ++i)
      for (int c = 0; c < D; ++c) {
        const double w0 = c0[i] * d0[i][c * k + v] + th[i] * dm[i][c * k + v];
        const double w1 = c0[i] * d1[i][c * k + v] + th[i] * d0[i][c * k + v];
        for (int r = 0; r < D; ++r) {
          acc[r] += Q.coeff(r, i * D + c) * w0;
          acc[r] += R.coeff(r, i * D + c) * w1;
        }
      }
    for (int r = 0; r < D; ++r) {
      for (int c = 0; c < D; ++c) acc[r] += P.coeff(r, c) * u0[c * k + v];
      out[r * k + v] = acc[r];
    }
  }
}

// A step's derivative, formed or factored (S^{-1} [L u0 + Bl w0 + Br w1]: the same pass with L,
// Bl, Br, then S^{-1} per vector), applied to k interleaved vectors.
template <int D, int DW, int KC = 0, class Target = detail::PortableTarget>
inline void multi_delay_step(const StepMap<D, DW>& s, const double* b, long current,
                             const DelayPlaces<DW / D>& places, long k, double* __restrict out) {
  multi_delay_block<D, DW, KC, Target>(s.P, s.Q, s.R, b, current, places, k, out);
}
template <int D, int DW, int KC = 0>
inline void multi_delay_step(const StepLinearisation<D, DW>& s, const double* b, long current,
                             const DelayPlaces<DW / D>& places, long k_runtime, double* __restrict out) {
  if (!s.factored) return multi_delay_step<D, DW, KC>(s.map, b, current, places, k_runtime, out);
  multi_delay_block<D, DW, KC>(s.sub.left, s.sub.bl, s.sub.br, b, current, places, k_runtime, out);
  const long k = KC > 0 ? KC : k_runtime;
  for (long v = 0; v < k; ++v) {  // out <- S^{-1} out, vector by vector
    Vec<D> rhs;
    for (int r = 0; r < D; ++r) rhs[r] = out[r * k + v];
    const Vec<D> x = s.sub.s.solve(rhs);
    for (int r = 0; r < D; ++r) out[r * k + v] = x[r];
  }
}

// The K steps of one map (formed step maps) on k interleaved vectors of the linear history b:
// step l reads slot M + l and the taps, writes slot M + l + 1. k = 1, 2, 4, 8, 16 at compile time.
template <int D, int DW, class Target = detail::PortableTarget>
inline void multi_delay_steps(const StepMap<D, DW>* maps, long K, long M,
                              const std::vector<HistoryGrid::DelayPosition>& delays, double* b, long k) {
  const DelayPlaces<DW / D> places(delays);
  const long stride = static_cast<long>(D) * k;
  auto run = [&]<int KC>() {
    for (long l = 0; l < K; ++l)
      multi_delay_step<D, DW, KC, Target>(maps[l], b, M + l, places, k, b + (M + l + 1) * stride);
  };
  switch (k) {
    case 1: return run.template operator()<1>();
    case 2: return run.template operator()<2>();
    case 4: return run.template operator()<4>();
    case 8: return run.template operator()<8>();
    case 16: return run.template operator()<16>();
    default: return run.template operator()<0>();
  }
}

}  // namespace delayspec
