#pragma once
// Which machine code runs the step-map kernels (block_kernel.hpp): the portable build (SSE2 on
// x86-64, what every CPU of the target runs), a path compiled for AVX2 + FMA in its own
// translation unit (src/engine/kernels/block_kernel_avx2.cpp), or the AVX-512 path: the AVX2 + FMA code plus one
// kernel of its own, the fused streaming apply_block for d = 2 and k a multiple of 8
// (src/engine/kernels/stream_kernel_avx512.cpp), chosen at run time. One binary runs everywhere and uses the
// widest path the CPU has.
//
// Choice (choose_kernel_path, once per Monodromy, at construction): the environment variable
// DELAYSPEC_KERNEL = `baseline`, `avx2` or `avx512` forces that path (the tests use it to check
// every path against the others; BadInput when the CPU cannot run it); unset, empty or `auto`
// takes the widest path the CPU supports (__builtin_cpu_supports: avx512f for avx512, avx2 and
// fma for both wide paths). Either way the choice is capped at the widest path compiled for the
// caller: avx512 for D = 2, avx2 for D = 1, for D = 1, 2 with 2-4 delays (kMultiDelayAvx2) and
// the Gram-Schmidt passes, baseline for a model of another shape (an equation model's, compiled
// outside the library). Any other value is BadInput naming it.
// The Gram-Schmidt passes of the Krylov-Schur backend and GMRES (src/engine/kernels/gram_schmidt_chunks.hpp)
// make the same choice per call, with their AVX2 + FMA code in src/engine/kernels/gram_schmidt_avx2.cpp.
//
// The paths compute the same sums; FMA rounds a*b + c once instead of twice, so they agree to
// rounding (tests/engine/test_kernel_dispatch.cpp), not bit for bit.
#include <vector>

#include "delayspec/grid.hpp"
#include "delayspec/step_map.hpp"

namespace delayspec {

// In order of width: each wide path runs the narrower one's code where it has none of its own.
enum class KernelPath { baseline, avx2, avx512 };

// "baseline", "avx2" or "avx512".
const char* kernel_path_name(KernelPath path);

// The path for a caller whose widest compiled path is `widest`: reads DELAYSPEC_KERNEL each call
// (cheap; callers cache the result). BadInput on an unknown value or a path the CPU cannot run.
KernelPath choose_kernel_path(KernelPath widest);

// Whether `path` runs the AVX2 + FMA code (both wide paths do).
inline bool runs_avx2_code(KernelPath path) { return path != KernelPath::baseline; }

namespace detail {
// The AVX2 + FMA instantiations of block_steps (block_kernel.hpp) for D = 1, 2 (k vectors; one
// vector runs the portable single_steps on every path, src/engine/kernels/block_kernel_avx2.cpp says why).
// Call only when runs_avx2_code(choose_kernel_path(..)).
void block_steps_avx2(const StepMap<1>* maps, long K, double* u, const double* delayed, double theta, long k);
void block_steps_avx2(const StepMap<2>* maps, long K, double* u, const double* delayed, double theta, long k);
// The streaming apply_block's K steps for d = 2 on k vectors, straight from X (n x k,
// column-major, leading dimension ldx) into Y (the result slots M + 1 .. M + K, i.e. Y's slots
// M + 1 - K .. M; the caller copies Y's slots 0 .. M - K), the transposes fused into the steps.
// Requires what streaming requires (Monodromy::apply_block_raw): j0 = delayed_slot(0),
// j0 - 1 >= 0 when theta != 0, j0 + K <= M, X and Y disjoint. The AVX-512 one (k a multiple of
// 8, src/engine/kernels/stream_kernel_avx512.cpp; call only on KernelPath::avx512), the AVX2 + FMA one (k a
// multiple of 4, src/engine/kernels/block_kernel_avx2.cpp) and the portable one (k even, src/engine/kernels/stream_kernel.cpp).
void stream_steps_avx512(const StepMap<2>* maps, long K, long M, long j0, double theta, const double* X, long ldx,
                         long k, double* Y, long ldy);
void stream_steps_avx2(const StepMap<2>* maps, long K, long M, long j0, double theta, const double* X, long ldx, long k,
                       double* Y, long ldy);
void stream_steps_portable(const StepMap<2>* maps, long K, long M, long j0, double theta, const double* X, long ldx,
                           long k, double* Y, long ldy);
// The AVX2 + FMA instantiations of multi_delay_steps (block_kernel.hpp) on k > 1 vectors for the
// shapes with several delays that have them (kMultiDelayAvx2: D = 1, 2 with 2-4 delays, the
// variable-pitch cutter's D = 2 with 4 among them). One vector runs the portable code, as above.
template <int D, int DW>
inline constexpr bool kMultiDelayAvx2 = (D == 1 || D == 2) && DW != D && DW % D == 0 && DW / D <= 4;
void multi_delay_steps_avx2(const StepMap<1, 2>* maps, long K, long M, const std::vector<HistoryGrid::DelayPosition>& delays,
                            double* b, long k);
void multi_delay_steps_avx2(const StepMap<1, 3>* maps, long K, long M, const std::vector<HistoryGrid::DelayPosition>& delays,
                            double* b, long k);
void multi_delay_steps_avx2(const StepMap<1, 4>* maps, long K, long M, const std::vector<HistoryGrid::DelayPosition>& delays,
                            double* b, long k);
void multi_delay_steps_avx2(const StepMap<2, 4>* maps, long K, long M, const std::vector<HistoryGrid::DelayPosition>& delays,
                            double* b, long k);
void multi_delay_steps_avx2(const StepMap<2, 6>* maps, long K, long M, const std::vector<HistoryGrid::DelayPosition>& delays,
                            double* b, long k);
void multi_delay_steps_avx2(const StepMap<2, 8>* maps, long K, long M, const std::vector<HistoryGrid::DelayPosition>& delays,
                            double* b, long k);
// dst[c ldd + r] = src[r lds + c] (r < rows, c < cols): interleave(X, ldx, n, k, b) is
// transpose_avx2(X, ldx, k, n, b, k), deinterleave(b, n, k, Y, ldy) is transpose_avx2(b, k, n, k, Y, ldy).
void transpose_avx2(const double* src, long lds, long rows, long cols, double* dst, long ldd);
}  // namespace detail

}  // namespace delayspec
