#pragma once
// Which machine code runs the step-map kernels (block_kernel.hpp): the portable build (SSE2 on
// x86-64, what every CPU of the target runs) or a path compiled for AVX2 + FMA in its own
// translation unit (src/block_kernel_avx2.cpp), chosen at run time. One binary runs everywhere
// and uses the wide path where the CPU has it.
//
// Choice (choose_kernel_path, once per Monodromy, at construction): the environment variable
// DELAYSPEC_KERNEL = `baseline` forces the portable path (the tests use it to check every path
// against the others); unset, empty or `auto` takes AVX2 + FMA when the CPU supports both
// (__builtin_cpu_supports) and an AVX2 path exists for the state dimension (D = 1, 2, the
// built-in models, compiled in the library); any other value is BadInput naming it.
// A model of another D compiled outside the library (an equation model) runs the portable path.
// The Gram-Schmidt passes of the Krylov-Schur backend and GMRES (src/gram_schmidt_chunks.hpp)
// make the same choice per call, with their AVX2 + FMA code in src/gram_schmidt_avx2.cpp.
//
// The paths compute the same sums; FMA rounds a*b + c once instead of twice, so they agree to
// rounding (tests/test_kernel_dispatch.cpp), not bit for bit.
#include "delayspec/step_map.hpp"

namespace delayspec {

enum class KernelPath { baseline, avx2 };

// "baseline" or "avx2".
const char* kernel_path_name(KernelPath path);

// The path for a state dimension that has (has_avx2_kernel) or lacks an AVX2 path: reads
// DELAYSPEC_KERNEL each call (cheap; callers cache the result). BadInput on an unknown value.
KernelPath choose_kernel_path(bool has_avx2_kernel);

namespace detail {
// The AVX2 + FMA instantiations of block_steps (block_kernel.hpp) for D = 1, 2 (k vectors; one
// vector runs the portable single_steps on every path, src/block_kernel_avx2.cpp says why).
// Call only when choose_kernel_path returned KernelPath::avx2.
void block_steps_avx2(const StepMap<1>* maps, long K, double* u, const double* delayed, double theta, long k);
void block_steps_avx2(const StepMap<2>* maps, long K, double* u, const double* delayed, double theta, long k);
// The streaming apply_block's K steps for d = 2 on k vectors, straight from X (n x k,
// column-major, leading dimension ldx) into Y (the result slots M + 1 .. M + K, i.e. Y's slots
// M + 1 - K .. M; the caller copies Y's slots 0 .. M - K), the transposes fused into the steps.
// Requires what streaming requires (Monodromy::apply_block_raw): j0 = delayed_slot(0),
// j0 - 1 >= 0 when theta != 0, j0 + K <= M, X and Y disjoint. The AVX2 + FMA one (k a multiple
// of 4, src/block_kernel_avx2.cpp) and the portable one (k even, src/stream_kernel.cpp).
void stream_steps_avx2(const StepMap<2>* maps, long K, long M, long j0, double theta, const double* X, long ldx, long k,
                       double* Y, long ldy);
void stream_steps_portable(const StepMap<2>* maps, long K, long M, long j0, double theta, const double* X, long ldx,
                           long k, double* Y, long ldy);
// dst[c ldd + r] = src[r lds + c] (r < rows, c < cols): interleave(X, ldx, n, k, b) is
// transpose_avx2(X, ldx, k, n, b, k), deinterleave(b, n, k, Y, ldy) is transpose_avx2(b, k, n, k, Y, ldy).
void transpose_avx2(const double* src, long lds, long rows, long cols, double* dst, long ldd);
}  // namespace detail

}  // namespace delayspec
