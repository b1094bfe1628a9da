// Monodromy::apply_block against its roofline on this machine (design.md 1.4).
//
//  BM_ApplyBlock/N/k   apply_block of the delayed Mathieu monodromy (d = 2, tau = T, K = N steps)
//                      to k vectors. Counters: ns per step per vector, and the achieved rates
//                      under the traffic model below.
//  BM_Triad/n          STREAM-like triad a = b + s c over n doubles per array: memory bandwidth
//                      (24 bytes per element moved, write-allocate not counted, as in STREAM).
//  BM_PeakFma          the kernel's own arithmetic, out += p a + q b + r c, on L1-resident
//                      vectors of length 32: the attainable flop rate with these compiler flags.
//
// Traffic model of one apply_block (n = d (N + 1), K steps, k vectors), in doubles:
//   interleave X into the buffer (read + write n k), each step reads the delayed slot and writes
//   the new one (2 d k) and reads its step map (3 d^2), de-interleave into Y (read + write n k):
//   bytes = 8 (4 n k + 2 d k K + 3 d^2 K).  flops = 6 d^2 k K (3 d^2 FMAs per step per vector).
// Roofline time = max(flops / peak_flops, bytes / bandwidth), bandwidth from BM_Triad at the
// working-set size (buffer (N + 1 + K) d k doubles + step maps).
#include <benchmark/benchmark.h>

#include <vector>

#include "delayspec/model_mathieu.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace {

using namespace delayspec;

Monodromy<2> mathieu_monodromy(int N) {
  const MathieuModel model({.kappa = 0.1, .delta = 1, .eps = 1, .b = 0.2});
  TrapezoidStepper<MathieuModel> stepper(model);
  StroboscopicMap<MathieuModel> map(stepper, make_grid(model.tau(), model.period(), N));
  return map.monodromy(Eigen::VectorXd::Zero(map.dimension()));
}

void BM_ApplyBlock(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const long k = state.range(1);
  const Monodromy<2> op = mathieu_monodromy(N);
  const long n = op.rows(), K = op.grid().K, d = 2;
  Eigen::MatrixXd X = Eigen::MatrixXd::Random(n, k), Y(n, k);
  for (auto _ : state) {
    op.apply_block(X, Y);
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
BENCHMARK(BM_ApplyBlock)->ArgsProduct({{1000, 4000}, {1, 4, 8, 16, 32}})->Unit(benchmark::kMicrosecond);

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
// 3 arrays of: 16 KiB (L1), 256 KiB (L2), 4 MiB (L3), 64 MiB (memory).
BENCHMARK(BM_Triad)->Arg(2048)->Arg(32768)->Arg(524288)->Arg(8388608)->Unit(benchmark::kMicrosecond);

void BM_PeakFma(benchmark::State& state) {
  constexpr long k = 32;
  alignas(64) double o[k] = {}, a[k], b[k], c[k];
  for (long v = 0; v < k; ++v) a[v] = 1e-3 * v, b[v] = 2e-3 * v, c[v] = 3e-3 * v;
  const double p = 0.999, q = 1e-3, r = -1e-3;
  long reps = 0;
  for (auto _ : state) {
    for (int rep = 0; rep < 1000; ++rep) {
      for (long v = 0; v < k; ++v) o[v] = 0.5 * o[v] + p * a[v] + q * b[v] + r * c[v];
      benchmark::DoNotOptimize(o);
    }
    reps += 1000;
  }
  // 3 FMAs + 1 multiply per element: count 7 flops (the kernel's 3 FMA = 6 flops plus the scaling)
  state.counters["GFlops"] = benchmark::Counter(static_cast<double>(reps) * k * 7 * 1e-9, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PeakFma);

}  // namespace

BENCHMARK_MAIN();
