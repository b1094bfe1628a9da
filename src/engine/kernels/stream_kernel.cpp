// The streaming apply_block for d = 2 and k even, fused with its transposes, in the portable
// build (stream_steps_portable, kernel_dispatch.hpp; the AVX2 + FMA one for k a multiple of 4 is
// in src/engine/kernels/block_kernel_avx2.cpp). Math as in block_kernel.hpp: step l (slot j = j0 + l) computes
//
//   b[M + l + 1] = P u + Q w0 + R w1,   u = b[M + l],  w0 = s[j],  w1 = s[j + 1],
//   s[i] = b[i] (theta = 0),  s[i] = (1 - theta) b[i] + theta b[i - 1] (theta != 0),
//
// (the step's w1 is the next step's w0: one interpolated slot per step).
//
// Layout. A V2 holds one component of one slot for 2 vectors (a 16-byte register: SSE2 on
// x86-64, the baseline every CPU has). Column v of X holds vector v's slots one after the other,
// 2 doubles each, so slot i of vectors v, v + 1 is one 16-byte load from each column, and their
// 2 x 2 transpose (2 unpacks) gives the slot's components as V2s; the step's output goes back
// the same way into Y. No staging buffer, no copies; u and the last slot read stay in registers
// from step to step. Two pairs of vectors run side by side and share the coefficients, which
// SSE2 can only broadcast with a load and a shuffle each (4 vectors: 12 shuffles for 24 products;
// 2 vectors would pay the same 12 for 12).
//
// GCC/Clang vector extensions, not intrinsics: the file builds on any target (on one without
// 16-byte vectors the compiler splits a V2 into scalars).
#include <cstring>

#include "delayspec/detail/kernel_dispatch.hpp"

namespace delayspec::detail {

namespace {

typedef double V2 __attribute__((vector_size(16)));

struct Slot2 {
  V2 c0, c1;  // components 0 and 1 of one slot, 2 vectors
};

inline V2 load2(const double* p) {
  V2 a;
  std::memcpy(&a, p, sizeof a);  // unaligned 16-byte load
  return a;
}
inline void store2(double* p, V2 a) { std::memcpy(p, &a, sizeof a); }
inline V2 splat(double a) { return V2{a, a}; }

// Slot i of the 2 columns x, x + ld: rows (c0, c1) of each column, transposed.
inline Slot2 load_slot(const double* x, long ld, long i) {
  const V2 a = load2(x + i), b = load2(x + ld + i);
  return {__builtin_shufflevector(a, b, 0, 2), __builtin_shufflevector(a, b, 1, 3)};
}
inline void store_slot(const Slot2& s, double* y, long ld, long i) {
  store2(y + i, __builtin_shufflevector(s.c0, s.c1, 0, 2));
  store2(y + ld + i, __builtin_shufflevector(s.c0, s.c1, 1, 3));
}

// (1 - theta) b + theta b_prev
inline Slot2 lerp(const Slot2& b, const Slot2& b_prev, V2 c0, V2 theta) {
  return {c0 * b.c0 + theta * b_prev.c0, c0 * b.c1 + theta * b_prev.c1};
}

// The 12 coefficients of one step map, broadcast. Eigen's 2 x 2 matrices are column-major.
struct Coefficients {
  V2 P[4], Q[4], R[4];  // (r, c) at [2 c + r]
  explicit Coefficients(const StepMap<2>& s) {
    for (int i = 0; i < 4; ++i) P[i] = splat(s.P.data()[i]), Q[i] = splat(s.Q.data()[i]), R[i] = splat(s.R.data()[i]);
  }
};

// Row r of out = Q w0 + R w1 + P u, the terms in step_block's order (Q, R interleaved, P u last).
inline V2 step_row(const Coefficients& m, int r, const Slot2& w0, const Slot2& w1, const Slot2& u) {
  V2 a = m.Q[r] * w0.c0;
  a += m.R[r] * w1.c0;
  a += m.Q[2 + r] * w0.c1;
  a += m.R[2 + r] * w1.c1;
  a += m.P[r] * u.c0;
  return a + m.P[2 + r] * u.c1;
}
inline Slot2 step(const Coefficients& m, const Slot2& w0, const Slot2& w1, const Slot2& u) {
  return {step_row(m, 0, w0, w1, u), step_row(m, 1, w0, w1, u)};
}

// The state of 2 vectors (columns X, X + ldx; results into Y, Y + ldy) between steps:
// u = b[M + l]; w = s[j] (the step's w0); last = b[j] (the next interpolation's b[i - 1]).
template <bool Interpolate>
struct Block2 {
  const double* X;
  double* Y;
  Slot2 u, w, last;

  Block2(const double* x, long ldx, double* y, long M, long j0, V2 c0, V2 th) : X(x), Y(y) {
    u = load_slot(X, ldx, 2 * M);
    last = load_slot(X, ldx, 2 * j0);
    w = last;
    if constexpr (Interpolate) w = lerp(last, load_slot(X, ldx, 2 * j0 - 2), c0, th);
  }

  // One step: x's slot j + 1 read at element `in` of each column, the result slot written at
  // element `out` of Y's.
  void advance(const Coefficients& m, long in, long ldx, long out, long ldy, V2 c0, V2 th) {
    Slot2 w1 = load_slot(X, ldx, in);
    if constexpr (Interpolate) {
      const Slot2 b = w1;
      w1 = lerp(b, last, c0, th);
      last = b;
    }
    u = step(m, w, w1, u);
    w = w1;
    store_slot(u, Y, ldy, out);
  }
};

// The K steps on 2 Pairs pairs of vectors (columns X, X + ldx, ...) side by side.
template <bool Interpolate, int Pairs>
void stream_pairs(const StepMap<2>* maps, long K, long M, long j0, double theta, const double* X, long ldx, double* Y,
                  long ldy) {
  const V2 c0 = splat(1 - theta), th = splat(theta);
  Block2<Interpolate> a(X, ldx, Y, M, j0, c0, th);
  Block2<Interpolate> b(X + (Pairs > 1 ? 2 * ldx : 0), ldx, Y + (Pairs > 1 ? 2 * ldy : 0), M, j0, c0, th);
  for (long l = 0; l < K; ++l) {
    const Coefficients m(maps[l]);
    const long in = 2 * (j0 + l + 1), out = 2 * (M + l + 1 - K);  // result slot i is Y's slot i - K
    a.advance(m, in, ldx, out, ldy, c0, th);
    if constexpr (Pairs > 1) b.advance(m, in, ldx, out, ldy, c0, th);
  }
}

template <bool Interpolate>
void stream_all(const StepMap<2>* maps, long K, long M, long j0, double theta, const double* X, long ldx, long k,
                double* Y, long ldy) {
  long v = 0;
  for (; v + 4 <= k; v += 4) stream_pairs<Interpolate, 2>(maps, K, M, j0, theta, X + v * ldx, ldx, Y + v * ldy, ldy);
  if (v < k) stream_pairs<Interpolate, 1>(maps, K, M, j0, theta, X + v * ldx, ldx, Y + v * ldy, ldy);
}

}  // namespace

void stream_steps_portable(const StepMap<2>* maps, long K, long M, long j0, double theta, const double* X, long ldx,
                           long k, double* Y, long ldy) {
  if (theta == 0) stream_all<false>(maps, K, M, j0, theta, X, ldx, k, Y, ldy);
  else stream_all<true>(maps, K, M, j0, theta, X, ldx, k, Y, ldy);
}

}  // namespace delayspec::detail
