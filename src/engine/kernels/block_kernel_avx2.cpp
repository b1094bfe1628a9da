// The AVX2 + FMA path of the step-map kernels (kernel_dispatch.hpp): the same template as the
// portable path (block_kernel.hpp's block_steps), compiled in this file only with -mavx2 -mfma
// (CMakeLists.txt), and the interleave copies as 4 x 4 register transposes (transpose_avx2). Only the block kernel: one
// vector (single_steps) is a recurrence bound by the latency of P u0, and there FMA is slower, not faster (bench_apply,
// docs/benchmarks.md: 2.8 ns against 2.2 ns per step), so perform_op runs the portable code on every path.
//
// Why a tag of internal linkage: a template instantiated here and, with the same arguments, in a
// portable file would be one weak symbol with two machine codes, and the linker would keep either
// one (AVX2 code in the portable path crashes a CPU without AVX2). Avx2Target lives in an
// unnamed namespace, so every instantiation below is local to this file. The kernels touch only
// plain arrays and Eigen's coeff() (always inlined here); check after a change that this object
// defines no weak symbol: `nm -C CMakeFiles/delayspec.dir/src/block_kernel_avx2.cpp.o | grep ' [WVu] '`
// must print nothing.
#if (defined(__x86_64__) || defined(__i386__)) && !(defined(__AVX2__) && defined(__FMA__))
#error "src/engine/kernels/block_kernel_avx2.cpp must be compiled with -mavx2 -mfma (CMakeLists.txt)"
#endif

#include <immintrin.h>

#include "delayspec/detail/block_kernel.hpp"
#include "delayspec/detail/kernel_dispatch.hpp"
#include "engine/kernels/stream_runs.hpp"

namespace delayspec::detail {

namespace {
struct Avx2Target {};
}  // namespace

void block_steps_avx2(const StepMap<1>* maps, long K, double* u, const double* delayed, double theta, long k) {
  block_steps<1, Avx2Target>(maps, K, u, delayed, theta, k);
}
void block_steps_avx2(const StepMap<2>* maps, long K, double* u, const double* delayed, double theta, long k) {
  block_steps<2, Avx2Target>(maps, K, u, delayed, theta, k);
}

// Several delays: the same template as the portable path (multi_delay_steps), one overload per
// shape (kernel_dispatch.hpp's kMultiDelayAvx2), each local to this file through Avx2Target.
#define DELAYSPEC_MULTI_DELAY_AVX2(D, DW)                                                                  \
  void multi_delay_steps_avx2(const StepMap<D, DW>* maps, long K, long M,                                  \
                              const std::vector<HistoryGrid::DelayPosition>& delays, double* b, long k) {  \
    static_assert(kMultiDelayAvx2<D, DW>);                                                                 \
    multi_delay_steps<D, DW, Avx2Target>(maps, K, M, delays, b, k);                                        \
  }
DELAYSPEC_MULTI_DELAY_AVX2(1, 2)
DELAYSPEC_MULTI_DELAY_AVX2(1, 3)
DELAYSPEC_MULTI_DELAY_AVX2(1, 4)
DELAYSPEC_MULTI_DELAY_AVX2(2, 4)
DELAYSPEC_MULTI_DELAY_AVX2(2, 6)
DELAYSPEC_MULTI_DELAY_AVX2(2, 8)
#undef DELAYSPEC_MULTI_DELAY_AVX2

// The streaming apply_block for d = 2 and k a multiple of 4, fused with its transposes
// (stream_steps_avx2, kernel_dispatch.hpp). Math as in block_kernel.hpp: step l (slot
// j = j0 + l) computes
//
//   b[M + l + 1] = P u + Q w0 + R w1,   u = b[M + l],  w0 = s[j],  w1 = s[j + 1],
//   s[i] = b[i] (theta = 0),  s[i] = (1 - theta) b[i] + theta b[i - 1] (theta != 0),
//
// (the step's w1 is the next step's w0: one interpolated slot per step). The sums are those of
// step_block in its order (Q, R interleaved, P u last).
//
// Layout. A __m256d holds one component of one slot for 4 vectors: Slot {c0, c1}. Column v of X
// holds vector v's slots one after the other, 2 doubles each, so 4 doubles at X + v ldx + 2 i
// are slots i and i + 1 of vector v: 4 such loads (4 columns) transposed in registers are slots
// i, i + 1 of the 4 vectors, components as rows. A pair of steps reads 4 loads + 8 shuffles per 4
// vectors and writes its two result slots as the inverse transpose + 4 stores straight into Y:
// no staging buffer, no copies. u and the last slot read stay in registers from step to step (in
// memory, the recurrence u -> out would add a store-to-load forwarding to its chain).
//
// Two blocks of 4 vectors run side by side and share each coefficient broadcast (a load that
// feeds 2 FMAs instead of 1), which also interleaves two recurrences: one block alone is bound by
// its chain u -> out, 2 dependent FMAs per step (16 cycles per pair against 12 for its 24 FMAs at
// 2 per cycle). bench_apply: 0.49 against 0.54 ns per step per vector (N = 1000, k = 8). The
// steps go in runs of 512 over all vectors (stream_runs.hpp).
namespace {

struct Slot {
  __m256d c0, c1;  // components 0 and 1 of one slot, 4 vectors
};

// Rows r0..r3 of a 4 x 4 block in, its columns out (in the same registers).
inline void transpose4(__m256d& r0, __m256d& r1, __m256d& r2, __m256d& r3) {
  const __m256d a0 = _mm256_unpacklo_pd(r0, r1), a1 = _mm256_unpackhi_pd(r0, r1);
  const __m256d a2 = _mm256_unpacklo_pd(r2, r3), a3 = _mm256_unpackhi_pd(r2, r3);
  r0 = _mm256_permute2f128_pd(a0, a2, 0x20);
  r1 = _mm256_permute2f128_pd(a1, a3, 0x20);
  r2 = _mm256_permute2f128_pd(a0, a2, 0x31);
  r3 = _mm256_permute2f128_pd(a1, a3, 0x31);
}

// Element i of 4 columns (x + v ld, v = 0..3): the first and last slots only.
inline __m256d gather4(const double* x, long ld, long i) {
  return _mm256_set_pd(x[3 * ld + i], x[2 * ld + i], x[ld + i], x[i]);
}
inline void scatter4(__m256d a, double* y, long ld, long i) {
  alignas(32) double t[4];
  _mm256_store_pd(t, a);
  for (int v = 0; v < 4; ++v) y[v * ld + i] = t[v];
}

// (1 - theta) b + theta b_prev
inline Slot lerp(const Slot& b, const Slot& b_prev, __m256d c0, __m256d theta) {
  return {_mm256_fmadd_pd(c0, b.c0, _mm256_mul_pd(theta, b_prev.c0)),
          _mm256_fmadd_pd(c0, b.c1, _mm256_mul_pd(theta, b_prev.c1))};
}

// Row r of out = Q w0 + R w1 + P u for two blocks a, b (each coefficient broadcast once).
// Eigen's 2 x 2 matrices are column-major: (r, c) at [2 c + r].
struct RowPair {
  __m256d a, b;
};
inline RowPair step_row(const StepMap<2>& s, int r, const Slot& w0a, const Slot& w1a, const Slot& ua, const Slot& w0b,
                        const Slot& w1b, const Slot& ub) {
  const double *P = s.P.data(), *Q = s.Q.data(), *R = s.R.data();
  __m256d c = _mm256_broadcast_sd(Q + r);
  __m256d a = _mm256_mul_pd(c, w0a.c0), b = _mm256_mul_pd(c, w0b.c0);
  c = _mm256_broadcast_sd(R + r);
  a = _mm256_fmadd_pd(c, w1a.c0, a), b = _mm256_fmadd_pd(c, w1b.c0, b);
  c = _mm256_broadcast_sd(Q + 2 + r);
  a = _mm256_fmadd_pd(c, w0a.c1, a), b = _mm256_fmadd_pd(c, w0b.c1, b);
  c = _mm256_broadcast_sd(R + 2 + r);
  a = _mm256_fmadd_pd(c, w1a.c1, a), b = _mm256_fmadd_pd(c, w1b.c1, b);
  c = _mm256_broadcast_sd(P + r);
  a = _mm256_fmadd_pd(c, ua.c0, a), b = _mm256_fmadd_pd(c, ub.c0, b);
  c = _mm256_broadcast_sd(P + 2 + r);
  return {_mm256_fmadd_pd(c, ua.c1, a), _mm256_fmadd_pd(c, ub.c1, b)};
}
// The step for two blocks (oa, ob) or, with b = a, one (the compiler drops b's duplicate sums).
inline void step(const StepMap<2>& s, const Slot& w0a, const Slot& w1a, const Slot& ua, const Slot& w0b,
                 const Slot& w1b, const Slot& ub, Slot& oa, Slot& ob) {
  const RowPair r0 = step_row(s, 0, w0a, w1a, ua, w0b, w1b, ub), r1 = step_row(s, 1, w0a, w1a, ua, w0b, w1b, ub);
  oa = {r0.a, r1.a};
  ob = {r0.b, r1.b};
}

// The state of 4 vectors (columns X .. X + 3 ldx of X, their results into Y's) before step l:
// u = b[M + l]; w = s[j] (the step's w0); last = b[j] (the next interpolation's b[i - 1]),
// j = j0 + l. u is x's slot M for l = 0 and else the result slot M + l, already in Y (Y's slot
// M + l - K): a run of steps can start at any l from X and Y alone, with the same values.
template <bool Interpolate>
struct Block4 {
  const double* X;
  double* Y;
  Slot u, w, last;

  Block4(const double* x, long ldx, double* y, long ldy, long M, long K, long j0, long l, __m256d c0, __m256d th)
      : X(x), Y(y) {
    const long iu = 2 * (M + l - K), j = j0 + l;
    u = l == 0 ? Slot{gather4(X, ldx, 2 * M), gather4(X, ldx, 2 * M + 1)}
               : Slot{gather4(Y, ldy, iu), gather4(Y, ldy, iu + 1)};
    last = {gather4(X, ldx, 2 * j), gather4(X, ldx, 2 * j + 1)};
    w = last;
    if constexpr (Interpolate) w = lerp(last, Slot{gather4(X, ldx, 2 * j - 2), gather4(X, ldx, 2 * j - 1)}, c0, th);
  }

  // The interpolated slots j + 1, j + 2 (x's slots read at element `in` of each column).
  void read_pair(long in, long ldx, __m256d c0, __m256d th, Slot& w1, Slot& w2) {
    const double* x = X + in;
    __m256d r0 = _mm256_loadu_pd(x), r1 = _mm256_loadu_pd(x + ldx);
    __m256d r2 = _mm256_loadu_pd(x + 2 * ldx), r3 = _mm256_loadu_pd(x + 3 * ldx);
    transpose4(r0, r1, r2, r3);  // slot j + 1 = (r0, r1), slot j + 2 = (r2, r3)
    w1 = {r0, r1};
    w2 = {r2, r3};
    if constexpr (Interpolate) {
      w1 = lerp(Slot{r0, r1}, last, c0, th);
      w2 = lerp(Slot{r2, r3}, Slot{r0, r1}, c0, th);
      last = {r2, r3};
    }
  }
  // The two results o1, o2 into Y at element `out` of each column; the state moves on.
  void write_pair(const Slot& o1, const Slot& o2, const Slot& w2, long out, long ldy) {
    w = w2;
    u = o2;
    __m256d y0 = o1.c0, y1 = o1.c1, y2 = o2.c0, y3 = o2.c1;
    transpose4(y0, y1, y2, y3);  // row v: vector v's two result slots
    double* y = Y + out;
    _mm256_storeu_pd(y, y0);
    _mm256_storeu_pd(y + ldy, y1);
    _mm256_storeu_pd(y + 2 * ldy, y2);
    _mm256_storeu_pd(y + 3 * ldy, y3);
  }
  // One step alone (K odd: the last one).
  void single(const StepMap<2>& s, long in, long ldx, long out, long ldy, __m256d c0, __m256d th) {
    Slot w1{gather4(X, ldx, in), gather4(X, ldx, in + 1)}, o;
    if constexpr (Interpolate) w1 = lerp(w1, last, c0, th);
    step(s, w, w1, u, w, w1, u, o, o);
    scatter4(o.c0, Y, ldy, out);
    scatter4(o.c1, Y, ldy, out + 1);
  }
};

// Steps l0 .. l1 - 1 on 8 vectors (Blocks = 2: columns X .. X + 7 ldx) or 4 (Blocks = 1).
template <bool Interpolate, int Blocks>
void stream_blocks(const StepMap<2>* maps, long l0, long l1, long K, long M, long j0, double theta, const double* X,
                   long ldx, double* Y, long ldy) {
  const __m256d c0 = _mm256_set1_pd(1 - theta), th = _mm256_set1_pd(theta);
  Block4<Interpolate> a(X, ldx, Y, ldy, M, K, j0, l0, c0, th);
  // With Blocks = 1 there is no second block of columns: b is a's (its construction reads only
  // a's columns; nothing of b is used). Columns 4..7 of X may not exist (ASan: a read past X's end).
  const long second = Blocks == 2 ? 4 : 0;
  Block4<Interpolate> b(X + second * ldx, ldx, Y + second * ldy, ldy, M, K, j0, l0, c0, th);
  long l = l0;
  for (; l + 1 < l1; l += 2) {  // steps l, l + 1: slots j + 1, j + 2 read, M + l + 1, M + l + 2 written
    const long in = 2 * (j0 + l + 1), out = 2 * (M + l + 1 - K);  // result slot i is Y's slot i - K
    Slot w1a, w2a, o1a, o2a, w1b, w2b, o1b, o2b;
    a.read_pair(in, ldx, c0, th, w1a, w2a);
    if constexpr (Blocks == 2) {
      b.read_pair(in, ldx, c0, th, w1b, w2b);
      step(maps[l], a.w, w1a, a.u, b.w, w1b, b.u, o1a, o1b);
      step(maps[l + 1], w1a, w2a, o1a, w1b, w2b, o1b, o2a, o2b);
      b.write_pair(o1b, o2b, w2b, out, ldy);
    } else {
      step(maps[l], a.w, w1a, a.u, a.w, w1a, a.u, o1a, o1b);
      step(maps[l + 1], w1a, w2a, o1a, w1a, w2a, o1a, o2a, o2b);
    }
    a.write_pair(o1a, o2a, w2a, out, ldy);
  }
  if (l < l1) {  // an odd run: the last step alone
    const long in = 2 * (j0 + l + 1), out = 2 * (M + l + 1 - K);
    a.single(maps[l], in, ldx, out, ldy, c0, th);
    if constexpr (Blocks == 2) b.single(maps[l], in, ldx, out, ldy, c0, th);
  }
}

template <bool Interpolate>
void stream_all(const StepMap<2>* maps, long K, long M, long j0, double theta, const double* X, long ldx, long k,
                double* Y, long ldy) {
  stream_in_runs<4>(K, k, [&](long l0, long l1, long v, auto blocks) {
    stream_blocks<Interpolate, decltype(blocks)::value>(maps, l0, l1, K, M, j0, theta, X + v * ldx, ldx, Y + v * ldy,
                                                        ldy);
  });
}

}  // namespace

void stream_steps_avx2(const StepMap<2>* maps, long K, long M, long j0, double theta, const double* X, long ldx, long k,
                       double* Y, long ldy) {
  if (theta == 0) stream_all<false>(maps, K, M, j0, theta, X, ldx, k, Y, ldy);
  else stream_all<true>(maps, K, M, j0, theta, X, ldx, k, Y, ldy);
}

// dst[c ldd + r] = src[r lds + c] for r < rows, c < cols: 4 x 4 tiles transposed in registers
// (4 loads, 8 shuffles, 4 stores per 16 doubles; the scalar loop moves one double per cycle),
// column tiles of ~16 KiB of dst so the 4-row passes find dst's lines still in L1.
void transpose_avx2(const double* src, long lds, long rows, long cols, double* __restrict dst, long ldd) {
  const long tile = rows >= 256 ? 8 : (2048 / rows) & ~3L;  // columns per tile: ~16 KiB of dst
  const long rows4 = rows & ~3L;
  for (long c0 = 0; c0 < cols; c0 += tile) {
    const long c1 = c0 + tile < cols ? c0 + tile : cols;
    const long c14 = c0 + ((c1 - c0) & ~3L);
    for (long r = 0; r < rows4; r += 4) {
      for (long c = c0; c < c14; c += 4) {
        const __m256d s0 = _mm256_loadu_pd(src + r * lds + c), s1 = _mm256_loadu_pd(src + (r + 1) * lds + c);
        const __m256d s2 = _mm256_loadu_pd(src + (r + 2) * lds + c), s3 = _mm256_loadu_pd(src + (r + 3) * lds + c);
        const __m256d a0 = _mm256_unpacklo_pd(s0, s1), a1 = _mm256_unpackhi_pd(s0, s1);  // (s0 s1)[0], [1]; [2], [3]
        const __m256d a2 = _mm256_unpacklo_pd(s2, s3), a3 = _mm256_unpackhi_pd(s2, s3);
        _mm256_storeu_pd(dst + c * ldd + r, _mm256_permute2f128_pd(a0, a2, 0x20));  // column c of src
        _mm256_storeu_pd(dst + (c + 1) * ldd + r, _mm256_permute2f128_pd(a1, a3, 0x20));
        _mm256_storeu_pd(dst + (c + 2) * ldd + r, _mm256_permute2f128_pd(a0, a2, 0x31));
        _mm256_storeu_pd(dst + (c + 3) * ldd + r, _mm256_permute2f128_pd(a1, a3, 0x31));
      }
      for (long c = c14; c < c1; ++c)
        for (long q = r; q < r + 4; ++q) dst[c * ldd + q] = src[q * lds + c];
    }
    for (long q = rows4; q < rows; ++q)
      for (long c = c0; c < c1; ++c) dst[c * ldd + q] = src[q * lds + c];
  }
}

}  // namespace delayspec::detail
