// Lyapunov exponents: the headline run (two exponents over 1e4 periods at N = 1000 on the
// impact model) and the two parts of one period it is made of, the QR of the n x k block
// (TangentQR) against applying the period's step maps to the same block (Monodromy::apply_block),
// plus Eigen's HouseholderQR on a column-major copy for comparison.
//
//   build/bench_lyapunov --benchmark_filter=Impact     # the headline run (~4 s, 2026-11-23)
//   build/bench_lyapunov --benchmark_filter='QR|Apply' # the per-period parts
#include <benchmark/benchmark.h>

#include <Eigen/QR>

#include "delayspec/lyapunov.hpp"
#include "delayspec/model_impact.hpp"
#include "delayspec/model_linear.hpp"
#include "delayspec/model_mathieu.hpp"

namespace ds = delayspec;

namespace {

ds::ImpactModel impact_model() {
  ds::ImpactParameters p;  // the default scene: paper parameters, tau = T, k = 0.2
  p.k = 0.2;
  p.x0 = -0.0566;
  p.v0 = 1.0101;
  return ds::ImpactModel(p);
}

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

}  // namespace

static void BM_LyapunovImpact(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const long periods = state.range(1);
  const auto model = impact_model();
  ds::StroboscopicMap<ds::ImpactModel> map(ds::TrapezoidStepper<ds::ImpactModel>(model),
                                           ds::make_grid(model.tau(), model.period(), N));
  ds::LyapunovOptions o;
  o.exponents = 2;
  o.periods = periods;
  o.transient = 0;
  double qr_fraction = 0, lambda1 = 0;
  for (auto _ : state) {
    auto r = ds::lyapunov_exponents(map, map.constant_history(model.initial_state()), o);
    qr_fraction = r.qr_seconds / r.seconds;
    lambda1 = r.per_period[0];
  }
  state.counters["qr_fraction"] = qr_fraction;
  state.counters["lambda1"] = lambda1;
  state.counters["ns_per_step"] = benchmark::Counter(
      static_cast<double>(periods) * N, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_LyapunovImpact)->Args({1000, 10000})->Args({1000, 1000})->Iterations(1)->Unit(benchmark::kSecond);

// The QR step alone (n = 2002: Mathieu or impact at N = 1000; k = 1..4 the common widths, 8 and
// 64 the compile-time and runtime extremes). Each iteration also copies the n x k source block
// back (the QR overwrites it): BM_BlockCopy is that copy alone.
static void BM_TangentQR(benchmark::State& state) {
  const long n = state.range(0);
  const int k = static_cast<int>(state.range(1));
  std::vector<double> source(n * k), block(n * k), q(n * k), log_r(k);
  ds::random_block(source.data(), n, k, 1);
  ds::TangentQR qr(block.data(), n, k);
  for (auto _ : state) {
    std::copy(source.begin(), source.end(), block.begin());
    qr.factorise(q.data(), log_r.data());
    benchmark::DoNotOptimize(q.data());
  }
}
BENCHMARK(BM_TangentQR)
    ->Args({2002, 1})
    ->Args({2002, 2})
    ->Args({2002, 3})
    ->Args({2002, 4})
    ->Args({2002, 8})
    ->Args({2002, 64})
    ->Args({402, 2})
    ->Unit(benchmark::kMicrosecond);

static void BM_BlockCopy(benchmark::State& state) {
  const long n = state.range(0);
  const int k = static_cast<int>(state.range(1));
  std::vector<double> source(n * k), block(n * k);
  ds::random_block(source.data(), n, k, 1);
  for (auto _ : state) {
    std::copy(source.begin(), source.end(), block.begin());
    benchmark::DoNotOptimize(block.data());
  }
}
BENCHMARK(BM_BlockCopy)->Args({2002, 2})->Args({2002, 8})->Unit(benchmark::kMicrosecond);

static void BM_EigenColumnMajorQR(benchmark::State& state) {
  const long n = state.range(0);
  const int k = static_cast<int>(state.range(1));
  std::vector<double> source(n * k), q(n * k);
  ds::random_block(source.data(), n, k, 1);
  Eigen::MatrixXd A(n, k), Q(n, k);
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(n, k);
  Eigen::Matrix<double, 1, Eigen::Dynamic> workspace(k);
  for (auto _ : state) {
    A = Eigen::Map<RowMajor>(source.data(), n, k);  // de-interleave
    qr.compute(A);
    Q.setIdentity();
    qr.householderQ().applyThisOnTheLeft(Q, workspace, false);
    Eigen::Map<RowMajor>(q.data(), n, k) = Q;  // interleave
    benchmark::DoNotOptimize(q.data());
  }
}
BENCHMARK(BM_EigenColumnMajorQR)->Args({2002, 2})->Args({2002, 8})->Args({402, 2})->Unit(benchmark::kMicrosecond);

// One period's step maps applied to the block: the linear part of a fused Lyapunov period
// (the fused loop also runs the nonlinear step, which dominates for the impact model).
static void BM_ApplyBlockPeriod(benchmark::State& state) {
  const int N = static_cast<int>((state.range(0) - 2) / 2);
  const int k = static_cast<int>(state.range(1));
  const auto model = impact_model();
  ds::StroboscopicMap<ds::ImpactModel> map(ds::TrapezoidStepper<ds::ImpactModel>(model),
                                           ds::make_grid(model.tau(), model.period(), N));
  const auto op = map.monodromy(map.constant_history(model.initial_state()));
  Eigen::MatrixXd X = Eigen::MatrixXd::Random(op.rows(), k), Y;
  for (auto _ : state) {
    op.apply_block(X, Y);
    benchmark::DoNotOptimize(Y.data());
  }
}
BENCHMARK(BM_ApplyBlockPeriod)->Args({2002, 2})->Args({2002, 8})->Args({402, 2})->Unit(benchmark::kMicrosecond);

// The cost of one fused Lyapunov step (trapezoid step, its step map, the k = 2 tangent vectors;
// the QR time excluded) for a scalar model against d = 2 models (issue 17 item 2): the CLI runs
// `lyapunov --set model=linear|mathieu|impact --set N=1000` of docs/benchmarks.md, 300 periods.
//   step_ns: (run time - QR time) / steps;  qr_ns: QR time / steps
template <class Model>
void lyapunov_step_cost(benchmark::State& state, const Model& model) {
  ds::StroboscopicMap<Model> map(ds::TrapezoidStepper<Model>(model), ds::make_grid(model.tau(), model.period(), 1000));
  ds::LyapunovOptions o;
  o.exponents = 2;
  o.periods = 300;
  o.transient = 10;
  double step_ns = 0, qr_ns = 0;
  for (auto _ : state) {
    const auto r = ds::lyapunov_exponents(map, map.constant_history(model.initial_state()), o);
    step_ns = (r.seconds - r.qr_seconds) / static_cast<double>(r.steps) * 1e9;
    qr_ns = r.qr_seconds / static_cast<double>(r.steps) * 1e9;
  }
  state.counters["step_ns"] = step_ns;
  state.counters["qr_ns"] = qr_ns;
}

static void BM_LyapunovStepLinear(benchmark::State& state) {
  ds::LinearParameters p;  // the docs' scalar run: a = -1, b = 0.5, tau = T = 7.834...
  p.tau = p.period = 7.834395644862327;
  lyapunov_step_cost(state, ds::LinearModel(p));
}
BENCHMARK(BM_LyapunovStepLinear)->Unit(benchmark::kMillisecond);

static void BM_LyapunovStepMathieu(benchmark::State& state) { lyapunov_step_cost(state, ds::MathieuModel()); }
BENCHMARK(BM_LyapunovStepMathieu)->Unit(benchmark::kMillisecond);

static void BM_LyapunovStepImpact(benchmark::State& state) {
  ds::ImpactParameters p;  // the docs' non-impacting run: tau = T, k = 0.2, history (1.2, 0)
  p.k = 0.2;
  p.x0 = 1.2;
  lyapunov_step_cost(state, ds::ImpactModel(p));
}
BENCHMARK(BM_LyapunovStepImpact)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
