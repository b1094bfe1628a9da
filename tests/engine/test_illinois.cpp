// The Illinois rule (include/delayspec/detail/illinois.hpp), the one the three bracketing
// locators share, on g(s) = e^s - 2 over [0, 2]: convex, so plain regula falsi keeps the end s = 2
// for ever and creeps up on the root ln 2 linearly (42 trials to 1e-12, counted by the same loop
// without the halving, below), while the halving makes it superlinear (9).
#include <gtest/gtest.h>

#include <cmath>

#include "delayspec/detail/illinois.hpp"

namespace {

using delayspec::detail::IllinoisValues;

double g(double s) { return std::exp(s) - 2; }

// Trials until the trial point is within 1e-12 of ln 2 (the root to a few ulps of 0.69), at most 200.
template <class Replace>
int trials_to_the_root(Replace replace) {
  double sa = 0, sb = 2;
  IllinoisValues v{g(sa), g(sb)};
  for (int trial = 1; trial <= 200; ++trial) {
    const double s = v.root(sa, sb), value = g(s);
    if (std::abs(s - std::log(2.0)) <= 1e-12) return trial;
    (replace(v, value) < 0 ? sa : sb) = s;
  }
  return 201;
}

TEST(Illinois, TheHalvingMakesRegulaFalsiSuperlinearOnAConvexFunction) {
  const int illinois = trials_to_the_root([](IllinoisValues& v, double value) { return v.replace(value); });
  // Plain regula falsi: the end of the value's sign replaced, nothing halved.
  const int plain = trials_to_the_root([](IllinoisValues& v, double value) {
    const int end = (value > 0) == (v.a > 0) ? -1 : 1;
    (end < 0 ? v.a : v.b) = value;
    return end;
  });
  EXPECT_LE(illinois, 10);
  EXPECT_GE(plain, 30);
}

TEST(Illinois, AValueReplacesTheEndOfItsSignAndASecondMoveOfThatEndHalvesTheOther) {
  IllinoisValues v{-1.0, 4.0};
  EXPECT_EQ(v.root(0.0, 1.0), 0.2);  // (0 * 4 - 1 * -1) / (4 - -1)
  EXPECT_EQ(v.replace(-0.5), -1);    // negative: the end a
  EXPECT_EQ(v.a, -0.5);
  EXPECT_EQ(v.b, 4.0);               // a's first move: b kept
  EXPECT_EQ(v.replace(-0.25), -1);   // a again: b halved
  EXPECT_EQ(v.b, 2.0);
  EXPECT_EQ(v.replace(1.0), 1);      // positive: the end b, a kept
  EXPECT_EQ(v.a, -0.25);
  EXPECT_EQ(v.b, 1.0);
  EXPECT_EQ(v.replace(0.5), 1);      // b again: a halved
  EXPECT_EQ(v.a, -0.125);
}

}  // namespace
