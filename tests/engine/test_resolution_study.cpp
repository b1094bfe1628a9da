// ResolutionStudy (resolution_study.hpp) through the public headers alone, no scene: floquet's
// error bars of the linear DDE x' = a x + b x(t - tau) against its exact multipliers (Lambert W,
// lambert_w.hpp, which the study does not use), the levels' grid rule, and a study level that is
// the same solve as floquet's at that N.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "delayspec/builtin_analyses.hpp"
#include "delayspec/lambert_w.hpp"
#include "delayspec/resolution_study.hpp"

using namespace delayspec;

namespace {

MapSettings resolution_map(int N) {
  MapSettings map;
  map.N = N;
  return map;
}

FloquetOptions dense_solver(int nev) {
  FloquetOptions o;
  o.nev = nev;
  o.solver = FloquetSolver::dense_lapack;
  return o;
}

// The exact multiplier nearest mu.
std::complex<double> nearest(const std::vector<std::complex<double>>& exact, std::complex<double> mu) {
  std::complex<double> best = exact.front();
  for (const auto& x : exact)
    if (std::abs(x - mu) < std::abs(best - mu)) best = x;
  return best;
}

}  // namespace

// x' = -x - 1.5 x(t - 1), T = tau = 1: a stable equilibrium whose leading multipliers are a complex
// pair (|mu| about 0.44). At N = 200 the trapezoid's error is ~ h^2 = 2.5e-5 and Richardson over
// N = 50, 100, 200 removes it: every bar must cover the exact error of its multiplier (the bar's
// contract, error_bars.hpp), the extrapolated values must be much nearer than mu_N (the h^2 term
// gone: at least 100x, where h^4 / h^2 = 2.5e-5 leaves room), the observed order 2, the verdict
// stable.
TEST(ResolutionStudy, FloquetErrorBarsCoverTheExactMultipliersOfALinearDde) {
  const auto analyses = builtin_analyses(LinearModel({-1.0, -1.5, 1.0, 1.0}));
  const int nev = 4;
  ResolutionStudy study(analyses, resolution_map(200), OrbitSettings{}, dense_solver(nev));
  const FloquetAtResolution at = study.floquet(/*with_error_bars=*/true);
  ASSERT_TRUE(at.bars);
  const ErrorBars& bars = *at.bars;
  EXPECT_EQ(bars.Ns, (std::vector<int>{50, 100, 200}));
  ASSERT_TRUE(bars.order);
  EXPECT_NEAR(*bars.order, 2.0, 0.05);
  EXPECT_EQ(bars.verdict, StabilityVerdict::stable);
  const auto exact = linear_dde_multipliers(-1.0, -1.5, 1.0, 1.0, 12);
  ASSERT_EQ(at.result.multipliers.size(), static_cast<size_t>(nev));
  for (int k = 0; k < nev; ++k) {
    const std::complex<double> mu = at.result.multipliers[k];
    const std::complex<double> x = nearest(exact, mu);
    const MultiplierErrorBar& bar = bars.bars[k];
    EXPECT_LE(std::abs(mu - x), bar.error_estimate) << "multiplier " << k;
    ASSERT_TRUE(bar.extrapolated) << "multiplier " << k;
    EXPECT_LE(std::abs(*bar.extrapolated - x), bar.extrapolated_error) << "multiplier " << k;
    EXPECT_LT(std::abs(*bar.extrapolated - x), 1e-2 * std::abs(mu - x)) << "multiplier " << k;
  }
  // The level at N is the study's record: its accuracy for every multiplier, its dimension d (N + 1)
  EXPECT_EQ(at.at_N.multipliers, at.result.multipliers);
  EXPECT_EQ(at.at_N.accuracy.size(), static_cast<size_t>(nev));
  EXPECT_EQ(study.dimension(200), 201);
}

// A study level is the same solve as floquet's at that N (the same orbit, operator and solver):
// bit for bit. And a delay/period ratio that needs multiples of a step count is a grid the study
// cannot make at the others: tau = 2, T = 1 needs N even.
TEST(ResolutionStudy, ALevelIsFloquetsSolveAndTheGridRuleIsTheModels) {
  const auto analyses = builtin_analyses(LinearModel({-1.0, -0.5, 2.0, 1.0}));
  ResolutionStudy study(analyses, resolution_map(40), OrbitSettings{}, dense_solver(3));
  EXPECT_TRUE(study.grid_fits(40));
  EXPECT_FALSE(study.grid_fits(41));
  const LevelResult level = study.level(40, 3);
  ASSERT_TRUE(level.failure.empty()) << level.failure;
  const FloquetAtResolution at = study.floquet(/*with_error_bars=*/false);
  EXPECT_FALSE(at.bars);
  EXPECT_EQ(level.multipliers, at.result.multipliers);
  EXPECT_EQ(level.accuracy, at.at_N.accuracy);
  // Without a failed orbit there is nothing to retry
  EXPECT_FALSE(study.retry(40, 3, 20));
}
