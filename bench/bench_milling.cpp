// Milling stability, seconds per chart point against the error of |mu_1| (issue 16, docs/milling.md):
// delayspec (step maps of the zero orbit, then the leading multiplier by the Krylov solver auto
// picks) side by side with the classic dense discretisations sdm0 and fdm1 (dense product of m step
// matrices and all its eigenvalues, classic_discretisation.hpp), at the benchmark points
//
//   /0: a/D = 1,    10000 rpm, 0.5 mm (h continuous)      /1: a/D = 0.05, 10000 rpm, 2.0 mm (window jumps)
//
// Counter `error`: relative error of |mu_1| against delayspec's Richardson extrapolation from
// N = 3200, 6400, 12800 (agrees with sdm0 and fdm1 extrapolated to 1e-9 at a/D = 1: test_milling).
// Read the rows at equal error, e.g. delayspec N = 1280 (error 2e-4) against sdm0/fdm1 m = 320.
//
//   build/bench_milling --benchmark_filter='Milling'
#include <benchmark/benchmark.h>

#include <cmath>
#include <complex>
#include <vector>

#include "delayspec/classic_discretisation.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/model_milling.hpp"
#include "delayspec/richardson.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace {

using namespace delayspec;

MillingModel benchmark_point(int index) {
  MillingParameters p;
  p.spindle_rpm = 10000;
  p.radial_immersion = index == 0 ? 1.0 : 0.05;
  p.depth = index == 0 ? 0.5e-3 : 2.0e-3;
  return MillingModel(p);
}

// One chart point of delayspec: step maps at the zero orbit, then |mu_1|.
double delayspec_modulus(const MillingModel& model, int N) {
  const StroboscopicMap<MillingModel> map(TrapezoidStepper<MillingModel>(model),
                                          make_grid(model.tau(), model.period(), N));
  FloquetOptions options;
  options.nev = 1;
  return std::abs(floquet_multipliers(map.monodromy(Eigen::VectorXd::Zero(map.dimension())), options).multipliers[0]);
}

double reference_modulus(int index) {
  static double cached[2] = {NAN, NAN};
  if (std::isnan(cached[index])) {
    const MillingModel model = benchmark_point(index);
    std::vector<double> h;
    std::vector<std::complex<double>> x;
    for (int N : {3200, 6400, 12800}) h.push_back(1.0 / N), x.push_back(delayspec_modulus(model, N));
    cached[index] = richardson_extrapolate(h, x).value.real();
  }
  return cached[index];
}

void BM_MillingDelayspec(benchmark::State& state) {
  const int index = static_cast<int>(state.range(0)), N = static_cast<int>(state.range(1));
  const MillingModel model = benchmark_point(index);
  double modulus = 0;
  for (auto _ : state) benchmark::DoNotOptimize(modulus = delayspec_modulus(model, N));
  state.counters["error"] = std::abs(modulus / reference_modulus(index) - 1);
}

template <ClassicMethod method>
void BM_MillingClassic(benchmark::State& state) {
  const int index = static_cast<int>(state.range(0)), m = static_cast<int>(state.range(1));
  const MillingModel model = benchmark_point(index);
  double modulus = 0;
  for (auto _ : state)
    benchmark::DoNotOptimize(modulus = std::abs(classic_multipliers(model, m, method, 1).multipliers[0]));
  state.counters["error"] = std::abs(modulus / reference_modulus(index) - 1);
}

void delayspec_sizes(benchmark::internal::Benchmark* b) {
  for (int point : {0, 1})
    for (int N : {80, 200, 320, 1280, 5120}) b->Args({point, N});
  b->Unit(benchmark::kMillisecond);
}
void classic_sizes(benchmark::internal::Benchmark* b) {
  for (int point : {0, 1})
    for (int m : {20, 40, 80, 160, 320, 640}) b->Args({point, m});
  b->Unit(benchmark::kMillisecond);
}

BENCHMARK(BM_MillingDelayspec)->Apply(delayspec_sizes);
BENCHMARK(BM_MillingClassic<ClassicMethod::sdm0>)->Apply(classic_sizes);
BENCHMARK(BM_MillingClassic<ClassicMethod::fdm1>)->Apply(classic_sizes);

}  // namespace

BENCHMARK_MAIN();
