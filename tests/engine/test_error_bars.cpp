// Error bars at one N from two coarser levels (error_bars.hpp), on sequences whose limit and
// error are known by construction: mu(N) = x + c h^2 + e h^4 (h = 1/N, the trapezoid's expansion)
// or with a first-order term the expansion does not expect. The bars must cover the actual error
// of the value at N and of the extrapolated value, and stay within 10x of it where the order is
// shown; the verdict must never be on the wrong side of the unit circle.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <functional>
#include <string>
#include <vector>

#include "delayspec/error_bars.hpp"
#include "delayspec/richardson.hpp"

namespace {

using namespace delayspec;
using cd = std::complex<double>;

// One synthetic multiplier: its limit and the coefficients of h^p1 and h^p2.
struct Sequence {
  cd limit;
  cd c1, c2;
  double p1 = 2, p2 = 4;
  cd at(int N) const {
    const double h = 1.0 / N;
    return limit + c1 * std::pow(h, p1) + c2 * std::pow(h, p2);
  }
};

std::vector<LevelResult> levels_of(const std::vector<Sequence>& sequences, const std::vector<int>& Ns) {
  std::vector<LevelResult> levels;
  for (int N : Ns) {
    LevelResult r;
    for (const Sequence& s : sequences) r.multipliers.push_back(s.at(N));
    levels.push_back(r);
  }
  return levels;
}

TEST(ErrorBars, CoarserLevelsAreValidGridsAtN4AndN2) {
  auto all = [](int) { return true; };
  EXPECT_EQ(coarser_levels(400, all), (std::vector<int>{100, 200}));
  EXPECT_EQ(coarser_levels(100000, all), (std::vector<int>{25000, 50000}));
  EXPECT_EQ(coarser_levels(100, all), (std::vector<int>{25, 50}));
  // A grid that needs multiples of 3: the largest valid one at or below.
  auto multiple_of_3 = [](int N) { return N % 3 == 0; };
  EXPECT_EQ(coarser_levels(400, multiple_of_3), (std::vector<int>{99, 198}));
  // Too coarse to be a level: left out.
  EXPECT_EQ(coarser_levels(12, all), (std::vector<int>{6}));
  EXPECT_TRUE(coarser_levels(7, all).empty());
}

TEST(ErrorBars, QuarteringLevelsAreN16AndN4OrN8AndN4BelowN256) {
  auto all = [](int) { return true; };
  const LevelSpacing q = LevelSpacing::quartering;
  EXPECT_EQ(coarser_levels(400, all, 4, q), (std::vector<int>{25, 100}));
  EXPECT_EQ(coarser_levels(100000, all, 4, q), (std::vector<int>{6250, 25000}));
  EXPECT_EQ(coarser_levels(200, all, 4, q), (std::vector<int>{25, 50}));
  EXPECT_EQ(coarser_levels(100, all, 4, q), (std::vector<int>{12, 25}));
  EXPECT_EQ(coarser_levels(20, all, 4, q), (std::vector<int>{5}));
  EXPECT_TRUE(coarser_levels(8, all, 4, q).empty());
}

TEST(ErrorBars, UnequalStepRatiosShowTheirOrder) {
  // Levels 25, 50, 200 (N/8, N/4, N) of x + c h^p: the differences' ratio is
  // (h1^p - h2^p) / (h0^p - h1^p), 3.2 for p = 2, where the geometric mean ratio's r^p is 8:
  // read with the equal-ratio formula this is "order 1.1", and the h^2 column was refused.
  for (double p : {1.0, 2.0, 4.0}) {
    const Sequence s{0.5, 1.0, 0.0, p, p};
    const double d1 = std::abs(s.at(50) - s.at(25)), d2 = std::abs(s.at(200) - s.at(50));
    EXPECT_NEAR(order_of_differences(1.0 / 25, 1.0 / 50, 1.0 / 200, d1, d2), p, 1e-9);
    // The differences of values ~0.5 that differ by d >= 1e-7 keep 1e-16 / 1e-7 relative: 1e-8 is loose.
    EXPECT_NEAR(difference_ratio(1.0 / 25, 1.0 / 50, 1.0 / 200, p) / (d2 / d1), 1.0, 1e-8);
  }
  // Equal ratios: the textbook log(d1 / d2) / log r.
  EXPECT_NEAR(order_of_differences(1.0 / 25, 1.0 / 100, 1.0 / 400, 16.0, 1.0), 2.0, 1e-9);
}

TEST(ErrorBars, BarsCoverTheActualErrorAndAreTightWhereTheOrderIsShown) {
  // A stable real multiplier, a complex pair, and one with a large h^4 term.
  const std::vector<Sequence> sequences = {
      {0.9, 2.0, -30.0}, {cd(0.3, 0.4), cd(-1.5, 0.7), cd(5, 5)}, {cd(0.3, -0.4), cd(-1.5, -0.7), cd(5, -5)},
      {0.2, 0.5, 40.0}};
  for (int N : {200, 400, 3200}) {
    const std::vector<int> Ns = [&] {
      std::vector<int> v = coarser_levels(N, [](int) { return true; });
      v.push_back(N);
      return v;
    }();
    const ErrorBars bars = error_bars(Ns, levels_of(sequences, Ns), RichardsonOptions{});
    ASSERT_EQ(bars.bars.size(), sequences.size());
    for (size_t k = 0; k < sequences.size(); ++k) {
      const double actual = std::abs(sequences[k].at(N) - sequences[k].limit);
      const MultiplierErrorBar& bar = bars.bars[k];
      EXPECT_GE(bar.error_estimate, actual) << "N = " << N << ", multiplier " << k;
      EXPECT_LE(bar.error_estimate, 10 * actual) << "N = " << N << ", multiplier " << k << ": " << bars.note;
      ASSERT_TRUE(bar.extrapolated.has_value()) << bars.note;
      // The extrapolated value's error: h^4 left over (and round-off); covered by its bar.
      EXPECT_GE(bar.extrapolated_error, std::abs(*bar.extrapolated - sequences[k].limit)) << "N = " << N;
    }
    EXPECT_EQ(bars.verdict, StabilityVerdict::stable);
    EXPECT_EQ(bars.deciding_N, 0);
  }
}

TEST(ErrorBars, TheVerdictIsNeverOnTheWrongSideOfTheUnitCircle) {
  const std::vector<int> Ns = {25, 100, 400};
  // Clearly outside.
  EXPECT_EQ(error_bars(Ns, levels_of({{1.1, 2.0, 0.0}, {0.5, 1.0, 0.0}}, Ns), {}).verdict, StabilityVerdict::unstable);
  // The limit is 1 - 1e-6 (stable), the value at N = 400 is 1 + 5.2e-6 (unstable): the bar
  // (~1e-5) holds the circle, so no verdict, and the N that would decide it is where the actual
  // error c / N^2 has fallen below the distance to the circle.
  const Sequence near{1 - 1e-6, 1.0, 0.0};
  const ErrorBars bars = error_bars(Ns, levels_of({near, {0.5, 1.0, 0.0}}, Ns), {});
  EXPECT_GT(std::abs(near.at(400)), 1.0);
  EXPECT_EQ(bars.verdict, StabilityVerdict::undecided) << bars.note;
  ASSERT_GT(bars.deciding_N, 400);
  EXPECT_LT(std::abs(near.at(static_cast<int>(bars.deciding_N)) - near.limit), 1e-6);
  // A small multiplier without a bar (two of its levels wildly apart) does not hold back the
  // verdict the leading one gives: the spectral radius bounds it in the limit too.
  std::vector<LevelResult> levels = levels_of({{0.5, 1.0, 0.0}, {1e-9, 0.0, 0.0}}, Ns);
  levels[0].multipliers[1] = 1e-9;  // differences 1e-10, then 2e-9: growing, no estimate
  levels[1].multipliers[1] = 1.1e-9;
  levels[2].multipliers[1] = 3.1e-9;
  const ErrorBars with_tiny = error_bars(Ns, levels, {});
  EXPECT_FALSE(std::isfinite(with_tiny.bars[1].error_estimate)) << with_tiny.note;
  EXPECT_EQ(with_tiny.verdict, StabilityVerdict::stable);
  // The same limit approached from inside: the value at N is stable, the bar still holds the circle.
  const Sequence inside{1 - 1e-6, -1.0, 0.0};
  EXPECT_EQ(error_bars(Ns, levels_of({inside}, Ns), {}).verdict, StabilityVerdict::undecided);
}

TEST(ErrorBars, AnUnexpectedOrderGivesABarFromTheDifferencesThatStillCoversTheError) {
  // First order where the expansion expects h^2 (a switching model's step without events): no
  // extrapolation; the bar is the column's own tail estimate.
  const std::vector<int> Ns = {25, 100, 400};
  const Sequence first_order{0.8, 3.0, 0.0, 1, 2};
  const ErrorBars bars = error_bars(Ns, levels_of({first_order}, Ns), RichardsonOptions{});
  ASSERT_EQ(bars.bars.size(), 1u);
  EXPECT_FALSE(bars.bars[0].extrapolated.has_value()) << bars.note;
  EXPECT_GE(bars.bars[0].error_estimate, std::abs(first_order.at(400) - first_order.limit));
  EXPECT_EQ(bars.verdict, StabilityVerdict::stable);  // 0.8 + 3/400 + bar < 1
  // Told the order is 1, the same data extrapolates.
  RichardsonOptions first;
  first.order = 1;
  first.order_step = 1;
  const ErrorBars told = error_bars(Ns, levels_of({first_order}, Ns), first);
  ASSERT_TRUE(told.bars[0].extrapolated.has_value()) << told.note;
  EXPECT_GE(told.bars[0].error_estimate, std::abs(first_order.at(400) - first_order.limit));
}

TEST(ErrorBars, AFailedCoarseLevelLeavesNoBarAndNoVerdict) {
  const std::vector<int> Ns = {25, 100, 400};
  std::vector<LevelResult> levels = levels_of({{0.5, 1.0, 0.0}}, Ns);
  levels[0] = LevelResult{};
  levels[0].failure = "orbit not found";
  levels[1] = LevelResult{};
  levels[1].failure = "orbit not found either";
  const ErrorBars bars = error_bars(Ns, levels, {});
  ASSERT_EQ(bars.bars.size(), 1u);
  EXPECT_TRUE(std::isinf(bars.bars[0].error_estimate));
  EXPECT_EQ(bars.verdict, StabilityVerdict::undecided);
  EXPECT_NE(bars.note.find("orbit not found either"), std::string::npos) << bars.note;
  EXPECT_EQ(bars.failures[1], "orbit not found either");
  // One coarse level left: two levels cannot show an order, so no bar either (never a guess).
  levels = levels_of({{0.5, 1.0, 0.0}}, Ns);
  levels[0] = LevelResult{};
  levels[0].failure = "orbit not found";
  EXPECT_TRUE(std::isinf(error_bars(Ns, levels, {}).bars[0].error_estimate));
}

}  // namespace

namespace {

TEST(ErrorBars, APlateauGivesNoEstimate) {
  // The impact orbit at tau = T, k = 0.55, events = off (first order), |mu_1| at N = 200, 400, 800,
  // 1600 as converge computed it: one jump, then differences of 1.9e-4 and 4.7e-5 on a plateau,
  // while the limit, 0.82558 (events = on, N = 12800, extrapolated +- 2.6e-5), is 1.2e-2 away
  // (issue 32, item 3). The tail of the column claimed 4.7e-4.
  RichardsonOptions first_order;
  first_order.order = 1;
  first_order.order_step = 1;
  const std::vector<double> h = {1.0 / 200, 1.0 / 400, 1.0 / 800, 1.0 / 1600};
  const std::vector<cd> x = {0.878994467421311, 0.813074764231099, 0.813260232550181, 0.813306915963554};
  const Extrapolation e = richardson_extrapolate(h, x, first_order);
  EXPECT_TRUE(std::isinf(e.error_estimate)) << e.error_estimate << ": " << e.note;
  EXPECT_NE(e.note.find("plateau"), std::string::npos) << e.note;
  // Equal values at two levels after a real difference: the same.
  const Extrapolation equal = richardson_extrapolate(h, {0.9, 0.85, 0.85, 0.849}, first_order);
  EXPECT_TRUE(std::isinf(equal.error_estimate)) << equal.note;
  // A sequence whose differences shrink at a rate the expansion allows keeps its estimate.
  const Extrapolation smooth = richardson_extrapolate(h, {0.9 + 3e-3, 0.9 + 1.2e-3, 0.9 + 0.45e-3, 0.9 + 0.2e-3},
                                                      first_order);
  EXPECT_TRUE(std::isfinite(smooth.error_estimate)) << smooth.note;
}

}  // namespace
