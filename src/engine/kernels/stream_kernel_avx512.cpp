// The AVX-512 path of the streaming apply_block for d = 2 and k a multiple of 8
// (stream_steps_avx512, kernel_dispatch.hpp), compiled in this file only with -mavx512f -mavx2
// -mfma (CMakeLists.txt). Everything else on the AVX-512 path (other k, d = 1, the staged and
// linear layouts, Gram-Schmidt) runs the AVX2 + FMA code: this file adds one kernel, not a copy.
// Math as in block_kernel.hpp and src/engine/kernels/block_kernel_avx2.cpp: step l (slot j = j0 + l) computes
//
//   b[M + l + 1] = P u + Q w0 + R w1,   u = b[M + l],  w0 = s[j],  w1 = s[j + 1],
//   s[i] = b[i] (theta = 0),  s[i] = (1 - theta) b[i] + theta b[i - 1] (theta != 0),
//
// with the sums in the order of step_block (Q, R interleaved, P u last), the AVX2 kernel's order.
//
// Layout. A __m512d holds one component of one slot for 8 vectors. 4 doubles at X + v ldx + 2 i
// are slots i, i + 1 of vector v (components A, B of slot i, C, D of slot i + 1). A pair of steps
// loads them from 8 columns as 4 zmm of 2 columns each, [v | v + 2] for v = 0, 4, 1, 5, and
// transposes them in two shuffle levels (an 8 x 4 transpose):
//
//   vshuff64x2: [0 | 2], [4 | 6] -> AB of vectors 0, 2, 4, 6 and CD of them (128-bit lanes);
//               [1 | 3], [5 | 7] -> the same for vectors 1, 3, 5, 7;
//   vunpck{l,h}pd of the even and odd halves -> A, B, C, D of vectors 0..7 in order.
//
// The two result slots go back the same way in reverse (vunpck, then vpermt2pd: vshuff64x2 cannot
// interleave lanes of its two sources), a 32-byte store per column. Per pair of steps and 8
// vectors: 8 loads, 8 shuffles, 8 stores and 24 FMAs, against the AVX2 kernel's 8 loads,
// 16 shuffles, 8 stores and 48 FMAs (docs/benchmarks.md, seventh sitting).
//
// Two blocks of 8 vectors run side by side where k allows (k a multiple of 16, and the 16 of
// k = 24): they share each coefficient broadcast and interleave two recurrences u -> out (2
// dependent FMAs per step: one block alone waits on that chain, 8 cycles per step). The steps go
// in runs of 512 over all vectors (stream_runs.hpp). bench_apply: 1.2-1.35x faster per vector
// than the AVX2 kernel for k = 8, 16, 32 (docs/benchmarks.md, seventh sitting).
//
// Symbols: as in src/engine/kernels/block_kernel_avx2.cpp, everything but stream_steps_avx512 is in an unnamed
// namespace (no weak symbol with AVX-512 code that the linker could pick for a portable caller):
// `nm -C CMakeFiles/delayspec.dir/src/stream_kernel_avx512.cpp.o | grep ' [WVu] '` prints nothing.
#if (defined(__x86_64__) || defined(__i386__)) && !(defined(__AVX512F__) && defined(__FMA__))
#error "src/engine/kernels/stream_kernel_avx512.cpp must be compiled with -mavx512f -mavx2 -mfma (CMakeLists.txt)"
#endif

// GCC 12's _mm512_undefined_pd (behind the insert, extract, shuffle and unpack intrinsics) is
// `__m512d __Y = __Y;`, which -Wmaybe-uninitialized reports at every use (GCC bug 105593, fixed
// in GCC 13): silenced for the header's own lines only.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <immintrin.h>
#pragma GCC diagnostic pop

#include "delayspec/detail/kernel_dispatch.hpp"
#include "engine/kernels/stream_runs.hpp"

namespace delayspec::detail {

namespace {

struct Slot {
  __m512d c0, c1;  // components 0 and 1 of one slot, 8 vectors
};

// Element i of 8 columns (x + v ld): the first and last slots only.
inline __m512d gather8(const double* x, long ld, long i) {
  return _mm512_set_pd(x[7 * ld + i], x[6 * ld + i], x[5 * ld + i], x[4 * ld + i], x[3 * ld + i], x[2 * ld + i],
                       x[ld + i], x[i]);
}
inline void scatter8(__m512d a, double* y, long ld, long i) {
  alignas(64) double t[8];
  _mm512_store_pd(t, a);
  for (int v = 0; v < 8; ++v) y[v * ld + i] = t[v];
}

// Columns v and v + 2 at element i of x: [x_v(i .. i + 3) | x_{v+2}(i .. i + 3)].
inline __m512d load_two(const double* x, long ld, long v) {
  return _mm512_insertf64x4(_mm512_castpd256_pd512(_mm256_loadu_pd(x + v * ld)), _mm256_loadu_pd(x + (v + 2) * ld), 1);
}
inline void store_two(__m512d a, double* y, long ld, long v) {
  _mm256_storeu_pd(y + v * ld, _mm512_castpd512_pd256(a));
  _mm256_storeu_pd(y + (v + 2) * ld, _mm512_extractf64x4_pd(a, 1));
}

// (1 - theta) b + theta b_prev
inline Slot lerp(const Slot& b, const Slot& b_prev, __m512d c0, __m512d theta) {
  return {_mm512_fmadd_pd(c0, b.c0, _mm512_mul_pd(theta, b_prev.c0)),
          _mm512_fmadd_pd(c0, b.c1, _mm512_mul_pd(theta, b_prev.c1))};
}

// The state of 8 vectors (columns X .. X + 7 ldx, their results into Y's) before step l, as
// Block4 of src/engine/kernels/block_kernel_avx2.cpp: u = b[M + l] (x's slot M for l = 0, else the result slot
// M + l, already in Y as Y's slot M + l - K); w = s[j], the step's w0; last = b[j], j = j0 + l.
template <bool Interpolate>
struct Block8 {
  const double* X = nullptr;
  double* Y = nullptr;
  Slot u, w, last;

  Block8() = default;
  Block8(const double* x, long ldx, double* y, long ldy, long M, long K, long j0, long l, __m512d c0, __m512d th)
      : X(x), Y(y) {
    const long iu = 2 * (M + l - K), j = j0 + l;
    u = l == 0 ? Slot{gather8(X, ldx, 2 * M), gather8(X, ldx, 2 * M + 1)}
               : Slot{gather8(Y, ldy, iu), gather8(Y, ldy, iu + 1)};
    last = {gather8(X, ldx, 2 * j), gather8(X, ldx, 2 * j + 1)};
    w = last;
    if constexpr (Interpolate) w = lerp(last, Slot{gather8(X, ldx, 2 * j - 2), gather8(X, ldx, 2 * j - 1)}, c0, th);
  }

  // The interpolated slots j + 1, j + 2 (x's slots read at element `in` of each column).
  void read_pair(long in, long ldx, __m512d c0, __m512d th, Slot& w1, Slot& w2) {
    const double* x = X + in;
    const __m512d z02 = load_two(x, ldx, 0), z46 = load_two(x, ldx, 4);
    const __m512d z13 = load_two(x, ldx, 1), z57 = load_two(x, ldx, 5);
    const __m512d ab_even = _mm512_shuffle_f64x2(z02, z46, _MM_SHUFFLE(2, 0, 2, 0));  // [A0 B0 | A2 B2 | A4 B4 | A6 B6]
    const __m512d cd_even = _mm512_shuffle_f64x2(z02, z46, _MM_SHUFFLE(3, 1, 3, 1));
    const __m512d ab_odd = _mm512_shuffle_f64x2(z13, z57, _MM_SHUFFLE(2, 0, 2, 0));  // [A1 B1 | A3 B3 | ..]
    const __m512d cd_odd = _mm512_shuffle_f64x2(z13, z57, _MM_SHUFFLE(3, 1, 3, 1));
    const Slot s1{_mm512_unpacklo_pd(ab_even, ab_odd), _mm512_unpackhi_pd(ab_even, ab_odd)};  // A0..A7, B0..B7
    const Slot s2{_mm512_unpacklo_pd(cd_even, cd_odd), _mm512_unpackhi_pd(cd_even, cd_odd)};
    w1 = s1;
    w2 = s2;
    if constexpr (Interpolate) {
      w1 = lerp(s1, last, c0, th);
      w2 = lerp(s2, s1, c0, th);
      last = s2;
    }
  }
  // The two results o1, o2 into Y at element `out` of each column; the state moves on.
  void write_pair(const Slot& o1, const Slot& o2, const Slot& w2, long out, long ldy) {
    w = w2;
    u = o2;
    const __m512i lo = _mm512_set_epi64(11, 10, 3, 2, 9, 8, 1, 0), hi = _mm512_set_epi64(15, 14, 7, 6, 13, 12, 5, 4);
    const __m512d ab_even = _mm512_unpacklo_pd(o1.c0, o1.c1), ab_odd = _mm512_unpackhi_pd(o1.c0, o1.c1);
    const __m512d cd_even = _mm512_unpacklo_pd(o2.c0, o2.c1), cd_odd = _mm512_unpackhi_pd(o2.c0, o2.c1);
    double* y = Y + out;
    store_two(_mm512_permutex2var_pd(ab_even, lo, cd_even), y, ldy, 0);  // [A0 B0 C0 D0 | A2 B2 C2 D2]
    store_two(_mm512_permutex2var_pd(ab_even, hi, cd_even), y, ldy, 4);
    store_two(_mm512_permutex2var_pd(ab_odd, lo, cd_odd), y, ldy, 1);
    store_two(_mm512_permutex2var_pd(ab_odd, hi, cd_odd), y, ldy, 5);
  }
  // One step's input slot alone (K odd: the last step), and its result.
  Slot read_one(long in, long ldx, __m512d c0, __m512d th) const {
    Slot w1{gather8(X, ldx, in), gather8(X, ldx, in + 1)};
    if constexpr (Interpolate) w1 = lerp(w1, last, c0, th);
    return w1;
  }
  void write_one(const Slot& o, long out, long ldy) {
    scatter8(o.c0, Y, ldy, out);
    scatter8(o.c1, Y, ldy, out + 1);
  }
};

// out[b] = P u[b] + Q w0[b] + R w1[b] for Blocks blocks of 8 vectors, each coefficient broadcast
// once. Eigen's 2 x 2 matrices are column-major: (r, c) at [2 c + r].
template <int Blocks>
inline void step(const StepMap<2>& s, const Slot* w0, const Slot* w1, const Slot* u, Slot* out) {
  const double *P = s.P.data(), *Q = s.Q.data(), *R = s.R.data();
  for (int r = 0; r < 2; ++r) {
    __m512d a[Blocks];
    __m512d c = _mm512_set1_pd(Q[r]);
    for (int b = 0; b < Blocks; ++b) a[b] = _mm512_mul_pd(c, w0[b].c0);
    c = _mm512_set1_pd(R[r]);
    for (int b = 0; b < Blocks; ++b) a[b] = _mm512_fmadd_pd(c, w1[b].c0, a[b]);
    c = _mm512_set1_pd(Q[2 + r]);
    for (int b = 0; b < Blocks; ++b) a[b] = _mm512_fmadd_pd(c, w0[b].c1, a[b]);
    c = _mm512_set1_pd(R[2 + r]);
    for (int b = 0; b < Blocks; ++b) a[b] = _mm512_fmadd_pd(c, w1[b].c1, a[b]);
    c = _mm512_set1_pd(P[r]);
    for (int b = 0; b < Blocks; ++b) a[b] = _mm512_fmadd_pd(c, u[b].c0, a[b]);
    c = _mm512_set1_pd(P[2 + r]);
    for (int b = 0; b < Blocks; ++b) (r == 0 ? out[b].c0 : out[b].c1) = _mm512_fmadd_pd(c, u[b].c1, a[b]);
  }
}

// Steps l0 .. l1 - 1 on 8 Blocks vectors (columns X .. X + (8 Blocks - 1) ldx).
template <bool Interpolate, int Blocks>
void stream_blocks(const StepMap<2>* maps, long l0, long l1, long K, long M, long j0, double theta, const double* X,
                   long ldx, double* Y, long ldy) {
  const __m512d c0 = _mm512_set1_pd(1 - theta), th = _mm512_set1_pd(theta);
  Block8<Interpolate> blk[Blocks];  // block b: columns 8 b .. 8 b + 7 (no column past X's k: ASan, 5410999)
  for (int b = 0; b < Blocks; ++b) blk[b] = {X + 8 * b * ldx, ldx, Y + 8 * b * ldy, ldy, M, K, j0, l0, c0, th};
  long l = l0;
  for (; l + 1 < l1; l += 2) {  // steps l, l + 1: slots j + 1, j + 2 read, M + l + 1, M + l + 2 written
    const long in = 2 * (j0 + l + 1), out = 2 * (M + l + 1 - K);  // result slot i is Y's slot i - K
    Slot w0[Blocks], u[Blocks], w1[Blocks], w2[Blocks], o1[Blocks], o2[Blocks];
    for (int b = 0; b < Blocks; ++b) {
      blk[b].read_pair(in, ldx, c0, th, w1[b], w2[b]);
      w0[b] = blk[b].w;
      u[b] = blk[b].u;
    }
    step<Blocks>(maps[l], w0, w1, u, o1);
    step<Blocks>(maps[l + 1], w1, w2, o1, o2);
    for (int b = 0; b < Blocks; ++b) blk[b].write_pair(o1[b], o2[b], w2[b], out, ldy);
  }
  if (l < l1) {  // an odd run: the last step alone
    const long in = 2 * (j0 + l + 1), out = 2 * (M + l + 1 - K);
    Slot w0[Blocks], u[Blocks], w1[Blocks], o[Blocks];
    for (int b = 0; b < Blocks; ++b) {
      w1[b] = blk[b].read_one(in, ldx, c0, th);
      w0[b] = blk[b].w;
      u[b] = blk[b].u;
    }
    step<Blocks>(maps[l], w0, w1, u, o);
    for (int b = 0; b < Blocks; ++b) blk[b].write_one(o[b], out, ldy);
  }
}

template <bool Interpolate>
void stream_all(const StepMap<2>* maps, long K, long M, long j0, double theta, const double* X, long ldx, long k,
                double* Y, long ldy) {
  stream_in_runs<8>(K, k, [&](long l0, long l1, long v, auto blocks) {
    stream_blocks<Interpolate, decltype(blocks)::value>(maps, l0, l1, K, M, j0, theta, X + v * ldx, ldx, Y + v * ldy,
                                                        ldy);
  });
}

}  // namespace

void stream_steps_avx512(const StepMap<2>* maps, long K, long M, long j0, double theta, const double* X, long ldx,
                         long k, double* Y, long ldy) {
  if (theta == 0) stream_all<false>(maps, K, M, j0, theta, X, ldx, k, Y, ldy);
  else stream_all<true>(maps, K, M, j0, theta, X, ldx, k, Y, ldy);
}

}  // namespace delayspec::detail
