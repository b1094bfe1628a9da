// The per-thread sin/cos memo of the models' forcing terms (detail/remembered_trig.hpp): every
// answer is std::sin / std::cos of the same argument, bit for bit, whether it comes from the
// table or not: first calls, repeats, arguments that evict each other from a set, signed zeros
// and non-finite arguments.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "delayspec/detail/remembered_trig.hpp"

namespace {

using delayspec::detail::remembered_cos;
using delayspec::detail::remembered_sin;

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

// Checks both functions on the arguments, in order; returns the number of mismatches.
int mismatches(const std::vector<double>& arguments) {
  int bad = 0;
  for (double x : arguments) {
    // volatile: keep GCC from sharing calls ([[gnu::const]]) so each one reaches the table
    volatile double s = remembered_sin(x), c = remembered_cos(x);
    bad += bits(s) != bits(std::sin(x)) || bits(c) != bits(std::cos(x));
  }
  return bad;
}

}  // namespace

// The step times of a Lyapunov run: l h and l h + h for K = 1000 steps per period, three periods
// (the second and third are answered from the table), then a larger grid of 20000 steps that
// overflows the 2^13 two-entry sets (evictions: recomputed values must still be right).
TEST(RememberedTrig, StepTimesRepeatedOverPeriodsAreExact) {
  std::vector<double> times;
  for (int K : {1000, 20000}) {
    const double h = 2 * 3.141592653589793 / K;
    for (int period = 0; period < 3; ++period)
      for (int l = 0; l < K; ++l) {
        times.push_back(l * h);
        times.push_back(l * h + h);
        times.push_back(0.802 * (l * h));  // a scaled argument (omega t) as the impact model's
      }
  }
  EXPECT_EQ(mismatches(times), 0);
}

// Random arguments, each used again after a random number of others: hits in the newer and the
// older entry of a set, misses after eviction.
TEST(RememberedTrig, RandomReuseIsExact) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-50, 50);
  std::vector<double> pool(30000);
  for (double& x : pool) x = u(rng);
  std::vector<double> arguments;
  std::uniform_int_distribution<std::size_t> pick(0, pool.size() - 1), few(0, 7);
  for (int i = 0; i < 200000; ++i) arguments.push_back(i % 3 == 0 ? pool[few(rng)] : pool[pick(rng)]);
  EXPECT_EQ(mismatches(arguments), 0);
}

TEST(RememberedTrig, SignedZerosAndNonFiniteArguments) {
  const double inf = std::numeric_limits<double>::infinity();
  // +0 then -0: sin(-0) = -0 must not be answered by the entry of +0
  EXPECT_EQ(mismatches({0.0, -0.0, 0.0, -0.0}), 0);
  EXPECT_TRUE(std::signbit(remembered_sin(-0.0)));
  EXPECT_TRUE(std::isnan(remembered_sin(inf)));
  EXPECT_TRUE(std::isnan(remembered_cos(-inf)));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(std::isnan(remembered_sin(nan)));
  EXPECT_TRUE(std::isnan(remembered_sin(nan)));  // a repeated NaN is still NaN
  EXPECT_EQ(mismatches({1.0, inf, 1.0}), 0);
}

// NaNs with any payload, on a new thread (a new, untouched table): a memo that marked empty
// entries with some NaN's bits would answer 0 for that NaN (the earlier one did, for
// 0x7ff8dead0000beef).
TEST(RememberedTrig, EveryNaNPayloadOnAFreshTable) {
  int not_nan = 0;
  std::thread fresh([&not_nan] {
    for (std::uint64_t payload : {0x7ff8dead0000beefull, 0x7ff8000000000001ull, 0xfff8000000000000ull, 0x0ull}) {
      const double x = std::bit_cast<double>(payload);
      volatile double s = remembered_sin(x), c = remembered_cos(x);
      not_nan += payload != 0 && (!std::isnan(s) || !std::isnan(c));
      not_nan += payload == 0 && (bits(s) != bits(std::sin(x)) || bits(c) != bits(std::cos(x)));
    }
  });
  fresh.join();
  EXPECT_EQ(not_nan, 0);
}

// Each thread has its own table: threads working on different arguments do not disturb each other.
TEST(RememberedTrig, ThreadsHaveTheirOwnTables) {
  int bad[2] = {0, 0};
  auto work = [&bad](int id) {
    std::vector<double> arguments;
    for (int period = 0; period < 3; ++period)
      for (int l = 0; l < 5000; ++l) arguments.push_back((id + 1) * 1e-3 * l);
    bad[id] = mismatches(arguments);
  };
  std::thread a(work, 0), b(work, 1);
  a.join();
  b.join();
  EXPECT_EQ(bad[0], 0);
  EXPECT_EQ(bad[1], 0);
}
