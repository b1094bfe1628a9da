// Floquet multipliers: Krylov (Spectra, ARPACK) on the matrix-free monodromy against dense
// LAPACK / Eigen, and the operator kernel itself (apply vs apply_block).
//
// System: the default scene's period-1 orbit of the impact oscillator (paper parameters,
// tau = T, k = 0.2), found by simulation once per N (setup, not timed).
//
//   BM_KrylovTop20/<solver>/<N>     top-20 multipliers, solver 0 = spectra, 1 = arpack, 4 = block
//   BM_DenseVsKrylov/<solver>/<N>   top-20 at N = 1000, 2000, solver 0..4 = spectra, arpack,
//                                   dense-lapack, dense-eigen, block; counter max_diff = largest
//                                   |mu_k - mu_k(dense-lapack)| / |mu_1| over the 20 (same run)
//   BM_Apply/<k>/<N>                ns per step per vector: k = 0 single-vector perform_op,
//                                   k >= 1 apply_block with k interleaved vectors
// Counters: applications (operator applications), restarts, residual (largest true residual),
// peak_rss_MB (getrusage ru_maxrss of the whole process so far: run one N per process for a
// per-case peak), basis_MB (n * ncv doubles, the Krylov basis).
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <chrono>
#include <map>
#include <memory>

#include "delayspec/floquet.hpp"
#include "delayspec/model_impact.hpp"
#include "delayspec/orbit_simulation.hpp"
#include "delayspec/stroboscopic_map.hpp"

using namespace delayspec;

namespace {

const Monodromy<2>& impact_monodromy(int N) {
  static std::map<int, std::unique_ptr<Monodromy<2>>> cache;
  auto& slot = cache[N];
  if (!slot) {
    ImpactModel model({.zeta = 0.01,
                       .e = 1.26,
                       .a = 0.7,
                       .beta = 28,
                       .omega = 0.802,
                       .k = 0.2,
                       .tau_over_T = 1,
                       .x0 = -0.0566,
                       .v0 = 1.0101});
    HistoryGrid grid = make_grid(model.tau(), model.period(), N);
    StroboscopicMap<ImpactModel> map(TrapezoidStepper<ImpactModel>(model), grid);
    PeriodicOrbit orbit = orbit_by_simulation(map, map.constant_history(model.initial_state()));
    slot = std::make_unique<Monodromy<2>>(map.monodromy(orbit.history));
  }
  return *slot;
}

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

const FloquetSolver kSolvers[] = {FloquetSolver::spectra, FloquetSolver::arpack, FloquetSolver::dense_lapack,
                                  FloquetSolver::dense_eigen, FloquetSolver::block};

void report(benchmark::State& state, const FloquetResult& r, long n) {
  double worst = 0;
  for (double x : r.residuals) worst = std::max(worst, x);
  state.counters["applications"] = static_cast<double>(r.operator_applications);
  state.counters["restarts"] = r.restarts;
  state.counters["residual"] = worst;
  state.counters["peak_rss_MB"] = peak_rss_mb();
  state.counters["basis_MB"] = static_cast<double>(n) * r.ncv * 8 / 1048576.0;
  state.counters["mu1"] = std::abs(r.multipliers[0]);
  state.counters["mu20"] = std::abs(r.multipliers.back());
  state.SetLabel(to_string(r.solver));
}

void BM_KrylovTop20(benchmark::State& state) {
  const Monodromy<2>& op = impact_monodromy(static_cast<int>(state.range(1)));
  FloquetOptions o;
  o.nev = 20;
  o.solver = kSolvers[state.range(0)];
  FloquetResult r;
  for (auto _ : state) r = floquet_multipliers(op, o);
  report(state, r, op.rows());
}

void BM_DenseVsKrylov(benchmark::State& state) {
  const Monodromy<2>& op = impact_monodromy(static_cast<int>(state.range(1)));
  FloquetOptions o;
  o.nev = 20;
  o.solver = kSolvers[state.range(0)];
  FloquetResult r;
  for (auto _ : state) r = floquet_multipliers(op, o);
  report(state, r, op.rows());
  // agreement with dense LAPACK on the same operator (computed once per N, outside the timing)
  static std::map<int, std::vector<std::complex<double>>> reference;
  auto& ref = reference[static_cast<int>(state.range(1))];
  if (ref.empty()) {
    FloquetOptions d = o;
    d.solver = FloquetSolver::dense_lapack;
    ref = o.solver == FloquetSolver::dense_lapack ? r.multipliers : floquet_multipliers(op, d).multipliers;
  }
  double diff = 0;
  for (size_t k = 0; k < ref.size(); ++k) diff = std::max(diff, std::abs(r.multipliers[k] - ref[k]));
  state.counters["max_diff"] = diff / std::abs(ref[0]);
}

void BM_Apply(benchmark::State& state) {
  const Monodromy<2>& op = impact_monodromy(static_cast<int>(state.range(1)));
  const long k = state.range(0);
  const long n = op.rows();
  double seconds = 0;
  if (k == 0) {
    Eigen::VectorXd x = start_vector(n, 1), y(n);
    for (auto _ : state) {
      const auto t0 = std::chrono::steady_clock::now();
      op.perform_op(x.data(), y.data());
      benchmark::DoNotOptimize(y.data());
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
  } else {
    Eigen::MatrixXd X(n, k), Y;
    for (long j = 0; j < k; ++j) X.col(j) = start_vector(n, static_cast<std::uint64_t>(j + 1));
    for (auto _ : state) {
      const auto t0 = std::chrono::steady_clock::now();
      op.apply_block(X, Y);
      benchmark::DoNotOptimize(Y.data());
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
  }
  const double vectors = static_cast<double>(std::max<long>(k, 1));
  state.counters["ns_per_step_per_vector"] =
      1e9 * seconds / (static_cast<double>(state.iterations()) * op.grid().K * vectors);
}

}  // namespace

BENCHMARK(BM_KrylovTop20)
    ->ArgsProduct({{0, 1, 4}, {10000, 100000, 1000000}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->MeasureProcessCPUTime();  // CPU time of all threads (OpenBLAS may use two inside ARPACK)
// dense-eigen (EigenSolver, single-threaded, ~3x dgeev) only at N = 1000
BENCHMARK(BM_DenseVsKrylov)
    ->Args({0, 1000})
    ->Args({1, 1000})
    ->Args({2, 1000})
    ->Args({3, 1000})
    ->Args({0, 2000})
    ->Args({1, 2000})
    ->Args({2, 2000})
    ->Args({4, 1000})
    ->Args({4, 2000})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->MeasureProcessCPUTime();
BENCHMARK(BM_Apply)->ArgsProduct({{0, 1, 4, 8, 16, 32}, {10000, 100000}})->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
