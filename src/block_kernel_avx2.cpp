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
#error "src/block_kernel_avx2.cpp must be compiled with -mavx2 -mfma (CMakeLists.txt)"
#endif

#include <immintrin.h>

#include "delayspec/detail/block_kernel.hpp"
#include "delayspec/detail/kernel_dispatch.hpp"

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
