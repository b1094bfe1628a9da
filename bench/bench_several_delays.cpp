// The cost of a second delay (issue 34): the same d = 2 linear oscillator with its two feedback
// terms read from one delay, and from two delays of different lengths (tau2 / tau1 irrational:
// both taps fractional), side by side in one run, N = 1000 steps per the longest delay.
//   Lyapunov: one fused step (trapezoid step, its derivative, two tangent vectors; QR excluded),
//             as bench_lyapunov's step_ns.
//   Apply:    the monodromy applied to one vector (perform_op) and to a block of 8 (apply_block),
//             ns per step per vector.
// Ratios two / one are what docs/benchmarks.md quotes (scripts/bench-several-delays.sh).
//
//   build/bench_several_delays
#include <array>
#include <chrono>
#include <cmath>

#include <benchmark/benchmark.h>

#include "delayspec/lyapunov.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace ds = delayspec;

namespace {

// x'' + c x' + x = k1 x(t - tau1) + k2 x'(t - tau2); One: tau2 = tau1 (one delay, the stock kernels).
struct OneDelay {
  static constexpr int d = 2;
  static constexpr bool has_switching = false, affine_in_state = true, is_linear = true;
  double c = 0.1, k1 = 0.3, k2 = -0.2, tau1 = std::sqrt(1.7), T = 1;
  double tau() const { return tau1; }
  double period() const { return T; }
  ds::Vec<2> f(int, double, const ds::Vec<2>& y, const ds::Vec<2>& z) const {
    return ds::Vec<2>(y[1], -c * y[1] - y[0] + k1 * z[0] + k2 * z[1]);
  }
  ds::Mat<2> A(int, double, const ds::Vec<2>&, const ds::Vec<2>&) const {
    return (ds::Mat<2>() << 0, 1, -1, -c).finished();
  }
  ds::Mat<2> B(int, double, const ds::Vec<2>&, const ds::Vec<2>&) const {
    return (ds::Mat<2>() << 0, 0, k1, k2).finished();
  }
  ds::Vec<2> initial_state() const { return ds::Vec<2>(1, 0); }
};

struct TwoDelays {
  static constexpr int d = 2;
  static constexpr int delay_count = 2;
  static constexpr bool has_switching = false, affine_in_state = true, is_linear = true;
  double c = 0.1, k1 = 0.3, k2 = -0.2, tau1 = 0.7, tau2 = std::sqrt(1.7), T = 1;
  std::array<double, 2> delays() const { return {tau1, tau2}; }
  double tau() const { return tau2; }
  double period() const { return T; }
  ds::Vec<2> f(int, double, const ds::Vec<2>& y, const ds::Vec<4>& z) const {
    return ds::Vec<2>(y[1], -c * y[1] - y[0] + k1 * z[0] + k2 * z[3]);
  }
  ds::Mat<2> A(int, double, const ds::Vec<2>&, const ds::Vec<4>&) const {
    return (ds::Mat<2>() << 0, 1, -1, -c).finished();
  }
  ds::RectMat<2, 4> B(int, double, const ds::Vec<2>&, const ds::Vec<4>&) const {
    ds::RectMat<2, 4> b = ds::RectMat<2, 4>::Zero();
    b(1, 0) = k1;
    b(1, 3) = k2;
    return b;
  }
  ds::Vec<2> initial_state() const { return ds::Vec<2>(1, 0); }
};

template <class Model>
ds::StroboscopicMap<Model> map_of(const Model& model) {
  return ds::StroboscopicMap<Model>(ds::TrapezoidStepper<Model>(model),
                                    ds::make_grid(ds::delays_of(model), model.period(), 1000));
}

template <class Model>
void lyapunov_step(benchmark::State& state) {
  const Model model;
  const auto map = map_of(model);
  ds::LyapunovOptions o;
  o.exponents = 2;
  o.periods = 3000;
  o.transient = 10;
  double step_ns = 0;
  for (auto _ : state) {
    const auto r = ds::lyapunov_exponents(map, map.constant_history(model.initial_state()), o);
    step_ns = (r.seconds - r.qr_seconds) / static_cast<double>(r.steps) * 1e9;
  }
  state.counters["step_ns"] = step_ns;
}

template <class Model>
void apply(benchmark::State& state) {
  const Model model;
  const auto map = map_of(model);
  const auto op = map.monodromy(Eigen::VectorXd::Zero(map.dimension()));
  const long k = state.range(0);
  Eigen::MatrixXd X = Eigen::MatrixXd::Random(op.rows(), k), Y;
  Eigen::VectorXd x = X.col(0), y;
  double seconds = 0;
  long runs = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    if (k == 1) {
      op.apply(x, y);
      benchmark::DoNotOptimize(y.data());
    } else {
      op.apply_block(X, Y);
      benchmark::DoNotOptimize(Y.data());
    }
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++runs;
  }
  state.counters["ns_per_step_vector"] = seconds / static_cast<double>(runs) / static_cast<double>(op.grid().K * k) * 1e9;
}

}  // namespace

static void BM_LyapunovStepOneDelay(benchmark::State& s) { lyapunov_step<OneDelay>(s); }
static void BM_LyapunovStepTwoDelays(benchmark::State& s) { lyapunov_step<TwoDelays>(s); }
BENCHMARK(BM_LyapunovStepOneDelay)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LyapunovStepTwoDelays)->Unit(benchmark::kMillisecond);
static void BM_ApplyOneDelay(benchmark::State& s) { apply<OneDelay>(s); }
static void BM_ApplyTwoDelays(benchmark::State& s) { apply<TwoDelays>(s); }
BENCHMARK(BM_ApplyOneDelay)->Arg(1)->Arg(8)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ApplyTwoDelays)->Arg(1)->Arg(8)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
