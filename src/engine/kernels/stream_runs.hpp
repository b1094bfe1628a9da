#pragma once
// The order in which the fused streaming kernels of the wide paths visit steps and vectors
// (stream_steps_avx2 in src/engine/kernels/block_kernel_avx2.cpp, stream_steps_avx512 in
// src/engine/kernels/stream_kernel_avx512.cpp): included by both and compiled with each file's flags. In an
// unnamed namespace, so each file keeps its own copy (no weak symbol whose machine code the
// linker could take from the other file; kernel_dispatch.hpp).
#include <type_traits>

namespace delayspec::detail {
namespace {

// Runs of kStreamRun steps (even: only the last run can be odd), all vectors per run: each block
// of vectors re-reads the run's step maps (kStreamRun 96 bytes = 48 KiB), which the first block
// brought into L1/L2; one pass per block over all K maps would read them from L3 at N = 4000
// (384 KiB of maps next to 1-4 MiB of X and Y). bench_apply, AVX2, N = 4000, k = 32: 0.61 -> 0.52
// ns per step per vector (runs of 128 and 256: 0.54, 0.51; k = 8, one block, unchanged); AVX-512:
// runs of 128 or 256 no different (docs/benchmarks.md, seventh sitting).
constexpr long kStreamRun = 512;

// Calls run_blocks(l0, l1, v, blocks) for every run of steps l0 .. l1 - 1 and, within it, for
// columns v .. v + blocks Width - 1: blocks = 2 (std::integral_constant) while 2 Width columns
// are left, then blocks = 1 for the last Width when k is not a multiple of 2 Width (k must be a
// multiple of Width). No call names a column past k - 1.
template <long Width, class RunBlocks>
void stream_in_runs(long K, long k, RunBlocks run_blocks) {
  for (long l0 = 0; l0 < K; l0 += kStreamRun) {
    const long l1 = l0 + kStreamRun < K ? l0 + kStreamRun : K;
    long v = 0;
    for (; v + 2 * Width <= k; v += 2 * Width) run_blocks(l0, l1, v, std::integral_constant<int, 2>{});
    if (v < k) run_blocks(l0, l1, v, std::integral_constant<int, 1>{});
  }
}

}  // namespace
}  // namespace delayspec::detail
