// Monodromy::apply_block against its roofline on this machine (design.md 1.4).
//
//  BM_ApplyBlock/N/k/path   apply_block of the delayed Mathieu monodromy (d = 2, tau = T, K = N
//                      steps) to k vectors, on kernel path 0 = main's kernel before issue 17
//                      (kernels_before.hpp), 1 = baseline (portable build), 2 = dispatched (the
//                      widest path the CPU has: AVX-512 or AVX2 + FMA; kernel_dispatch.hpp), 3 =
//                      AVX2 + FMA forced (the same as 2 on a CPU without AVX-512). Counters: ns per
//                      step per vector, and the achieved rates under the traffic model below.
//  BM_PerformOp/N/path single-vector perform_op on the same operator and paths: ns per step.
//  BM_Triad/n          STREAM-like triad a = b + s c over n doubles per array: memory bandwidth
//                      (24 bytes per element moved, write-allocate not counted, as in STREAM).
//  BM_PeakFma/isa      the kernel's own arithmetic, out += p a + q b + r c, on L1-resident
//                      vectors of length 32: the attainable flop rate with the default flags
//                      (isa 0) and with AVX2 + FMA (isa 1, what the dispatched path may use).
//
// Traffic model of one apply_block (n = d (N + 1), K steps, k vectors), in doubles:
//   interleave X into the buffer (read + write n k), each step reads the delayed slot and writes
//   the new one (2 d k) and reads its step map (3 d^2), de-interleave into Y (read + write n k):
//   bytes = 8 (4 n k + 2 d k K + 3 d^2 K).  flops = 6 d^2 k K (3 d^2 FMAs per step per vector).
// Roofline time = max(flops / peak_flops, bytes / bandwidth), bandwidth from BM_Triad at the
// working-set size (buffer (N + 1 + K) d k doubles + step maps).
// The fused streaming kernels (d = 2, k even: no buffer, no copies) move only X once, Y once and
// the maps: bytes = 8 (2 n k + 3 d^2 K); against them the model above is not a bound, the flop
// ceiling is the best BM_PeakFmaPipes over all paths (whichever path is judged) and the
// bandwidth the triad at X + Y + maps (docs/benchmarks.md, sixth and seventh sittings for
// apply_block). The model_GBps counter keeps the model above.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <vector>

#include "kernels_before.hpp"
#include "delayspec/model_mathieu.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace {

using namespace delayspec;

enum Variant { kBefore = 0, kBaseline = 1, kDispatched = 2, kAvx2 = 3 };

// The operator on the kernel path of `variant` (DELAYSPEC_KERNEL is read at construction).
Monodromy<2> mathieu_monodromy(int N, long variant = kDispatched) {
  if (variant == kBaseline) setenv("DELAYSPEC_KERNEL", "baseline", 1);
  else if (variant == kAvx2) setenv("DELAYSPEC_KERNEL", "avx2", 1);
  else unsetenv("DELAYSPEC_KERNEL");
  const MathieuModel model({.kappa = 0.1, .delta = 1, .eps = 1, .b = 0.2});
  TrapezoidStepper<MathieuModel> stepper(model);
  StroboscopicMap<MathieuModel> map(stepper, make_grid(model.tau(), model.period(), N));
  return map.monodromy(Eigen::VectorXd::Zero(map.dimension()));
}

void BM_ApplyBlock(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const long k = state.range(1), variant = state.range(2);
  const Monodromy<2> op = mathieu_monodromy(N, variant);
  state.SetLabel(variant == kBefore ? "before" : kernel_path_name(op.kernel_path()));
  const long n = op.rows(), K = op.grid().K, d = 2;
  Eigen::MatrixXd X = Eigen::MatrixXd::Random(n, k), Y(n, k);
  std::vector<double> work;
  for (auto _ : state) {
    if (variant == kBefore) before::apply_block(op, X.data(), k, Y.data(), work);
    else op.apply_block(X, Y);
    benchmark::DoNotOptimize(Y.data());
    benchmark::ClobberMemory();
  }
  const double iters = static_cast<double>(state.iterations());
  const double bytes = 8.0 * (4.0 * n * k + 2.0 * d * k * K + 3.0 * d * d * K);
  const double flops = 6.0 * d * d * k * K;
  state.counters["ns_per_step_per_vec"] =
      benchmark::Counter(iters * K * k * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["model_GBps"] = benchmark::Counter(iters * bytes * 1e-9, benchmark::Counter::kIsRate);
  state.counters["GFlops"] = benchmark::Counter(iters * flops * 1e-9, benchmark::Counter::kIsRate);
  state.counters["working_set_KiB"] = (8.0 * ((N + 1 + K) * d * k + 9.0 * d * d * K / 3.0)) / 1024.0;
}
BENCHMARK(BM_ApplyBlock)
    ->ArgsProduct({{1000, 4000}, {1, 2, 4, 8, 16, 32}, {0, 1, 2, 3}})
    ->Unit(benchmark::kMicrosecond);

void BM_PerformOp(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const long variant = state.range(1);
  const Monodromy<2> op = mathieu_monodromy(N, variant);
  state.SetLabel(variant == kBefore ? "before" : kernel_path_name(op.kernel_path()));
  const long n = op.rows(), K = op.grid().K;
  Eigen::VectorXd x = Eigen::VectorXd::Random(n), y(n);
  std::vector<double> work;
  for (auto _ : state) {
    if (variant == kBefore) before::perform_op(op, x.data(), y.data(), work);
    else op.perform_op(x.data(), y.data());
    benchmark::DoNotOptimize(y.data());
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_step"] = benchmark::Counter(static_cast<double>(state.iterations()) * K * 1e-9,
                                                     benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_PerformOp)->ArgsProduct({{1000, 4000}, {0, 1, 2}})->Unit(benchmark::kMicrosecond);

void BM_Triad(benchmark::State& state) {
  const long n = state.range(0);
  std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
  const double s = 3.0;
  for (auto _ : state) {
    for (long i = 0; i < n; ++i) a[i] = b[i] + s * c[i];  // a = b + s c
    benchmark::DoNotOptimize(a.data());
    benchmark::ClobberMemory();
  }
  state.counters["GBps"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * 24.0 * n * 1e-9, benchmark::Counter::kIsRate);
  state.counters["KiB_total"] = 24.0 * n / 1024.0;
}
// 3 arrays of: 16 KiB (L1), 256 KiB (L2), 4 MiB (L3), 64 MiB (memory); then 3 arrays totalling
// BM_ApplyBlock's streaming working sets (X + Y + maps, d = 2, tau = T) for k = 8, 16, 32 at
// N = 1000 (352, 608, 1121 KB) and N = 4000 (1408, 2432, 4480 KB): the bandwidth at the
// kernel's own size, between the levels (docs/benchmarks.md, seventh sitting).
BENCHMARK(BM_Triad)->Arg(2048)->Arg(32768)->Arg(524288)->Arg(8388608)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Triad)->Arg(14677)->Arg(25355)->Arg(46709)->Arg(58677)->Arg(101355)->Arg(186709)->Unit(
    benchmark::kMicrosecond);

// 1000 passes of o = 0.5 o + p a + q b + r c over 32 doubles; the same source compiled twice.
#define DELAYSPEC_PEAK_FMA_BODY                                                       \
  for (int rep = 0; rep < 1000; ++rep) {                                              \
    for (long v = 0; v < 32; ++v) o[v] = 0.5 * o[v] + p * a[v] + q * b[v] + r * c[v]; \
    benchmark::DoNotOptimize(o);                                                      \
  }
void peak_fma_default(double* o, const double* a, const double* b, const double* c, double p, double q, double r) {
  DELAYSPEC_PEAK_FMA_BODY
}
__attribute__((target("avx2,fma"))) void peak_fma_avx2(double* o, const double* a, const double* b, const double* c,
                                                       double p, double q, double r) {
  DELAYSPEC_PEAK_FMA_BODY
}

void BM_PeakFma(benchmark::State& state) {
  constexpr long k = 32;
  alignas(64) double o[k] = {}, a[k], b[k], c[k];
  for (long v = 0; v < k; ++v) a[v] = 1e-3 * v, b[v] = 2e-3 * v, c[v] = 3e-3 * v;
  const double p = 0.999, q = 1e-3, r = -1e-3;
  const bool avx2 = state.range(0) == 1;
  if (avx2 && !(__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))) {
    state.SkipWithError("this CPU has no AVX2 + FMA");
    return;
  }
  long reps = 0;
  for (auto _ : state) {
    if (avx2) peak_fma_avx2(o, a, b, c, p, q, r);
    else peak_fma_default(o, a, b, c, p, q, r);
    reps += 1000;
  }
  // 3 FMAs + 1 multiply per element: count 7 flops (the kernel's 3 FMA = 6 flops plus the scaling)
  state.counters["GFlops"] = benchmark::Counter(static_cast<double>(reps) * k * 7 * 1e-9, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PeakFma)->Arg(0)->Arg(1);

// The FP pipes' own peak: 12 independent accumulators a = a y + z held in registers, no memory
// access, 2 flops per element: with the default flags a multiply and an add on 16-byte vectors
// (isa 0), with AVX2 + FMA one 32-byte FMA (isa 1), with AVX-512F one 64-byte FMA (isa 2; on a
// CPU with full-width 512-bit FMA units twice isa 1). BM_PeakFma above runs the kernel-shaped loop
// (4 loads and a store per 4 arithmetic instructions, a multiply counted as 1 of 7 flops): a
// ceiling of that loop, below this one. docs/benchmarks.md says which one bounds what.
typedef double V2 __attribute__((vector_size(16)));
typedef double V4 __attribute__((vector_size(32)));
#define DELAYSPEC_PEAK_PIPES_BODY(V)                                                         \
  V a0 = s + 0.1, a1 = s + 0.2, a2 = s + 0.3, a3 = s + 0.4, a4 = s + 0.5, a5 = s + 0.6;      \
  V a6 = s + 0.7, a7 = s + 0.8, a8 = s + 0.9, a9 = s + 1.0, a10 = s + 1.1, a11 = s + 1.2;    \
  for (long i = 0; i < reps; ++i) {                                                          \
    a0 = a0 * y + z, a1 = a1 * y + z, a2 = a2 * y + z, a3 = a3 * y + z;                      \
    a4 = a4 * y + z, a5 = a5 * y + z, a6 = a6 * y + z, a7 = a7 * y + z;                      \
    a8 = a8 * y + z, a9 = a9 * y + z, a10 = a10 * y + z, a11 = a11 * y + z;                  \
  }                                                                                          \
  const V t = ((a0 + a1) + (a2 + a3)) + ((a4 + a5) + (a6 + a7)) + ((a8 + a9) + (a10 + a11)); \
  return t[0];
double peak_pipes_default(long reps, double s0) {
  const V2 s = {s0, s0}, y = s * 0.999, z = s * 1e-3;
  DELAYSPEC_PEAK_PIPES_BODY(V2)
}
__attribute__((target("avx2,fma"))) double peak_pipes_avx2(long reps, double s0) {
  const V4 s = {s0, s0, s0, s0}, y = s * 0.999, z = s * 1e-3;
  DELAYSPEC_PEAK_PIPES_BODY(V4)  // a y + z contracts to one FMA (-ffp-contract=fast, GCC's default)
}
typedef double V8 __attribute__((vector_size(64)));
__attribute__((target("avx512f"))) double peak_pipes_avx512(long reps, double s0) {
  const V8 s = {s0, s0, s0, s0, s0, s0, s0, s0}, y = s * 0.999, z = s * 1e-3;
  DELAYSPEC_PEAK_PIPES_BODY(V8)  // one 64-byte FMA per accumulator (zmm)
}

void BM_PeakFmaPipes(benchmark::State& state) {
  const long isa = state.range(0);
  if (isa == 1 && !(__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))) {
    state.SkipWithError("this CPU has no AVX2 + FMA");
    return;
  }
  if (isa == 2 && !__builtin_cpu_supports("avx512f")) {
    state.SkipWithError("this CPU has no AVX-512F");
    return;
  }
  constexpr long reps = 100000;
  double s0 = 1.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(s0);
    const double r = isa == 2   ? peak_pipes_avx512(reps, s0)
                     : isa == 1 ? peak_pipes_avx2(reps, s0)
                                : peak_pipes_default(reps, s0);
    benchmark::DoNotOptimize(r);
  }
  const double width = isa == 2 ? 8 : isa == 1 ? 4 : 2;  // doubles per vector
  const double elements = static_cast<double>(state.iterations()) * reps * 12 * width;
  state.counters["GFlops"] = benchmark::Counter(elements * 2 * 1e-9, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PeakFmaPipes)->Arg(0)->Arg(1)->Arg(2);

}  // namespace

BENCHMARK_MAIN();
