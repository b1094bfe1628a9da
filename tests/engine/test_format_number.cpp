// format_number(x): the shortest of the %.{1..17}g spellings of x that strtod reads back as x.
// Checked against that definition computed here with the C library's own snprintf and strtod, on
// doubles of every kind: random bit patterns (all exponents, subnormals), short decimals as a
// person types them, integers and powers of ten around the %g switch to exponent notation, powers
// of two and of ten with their neighbours (format_number's fast path: errors.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "delayspec/errors.hpp"

namespace {

std::string shortest_printf_spelling(double value) {
  char buffer[64];
  std::string best;
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
    const bool exact = !std::isfinite(value) || std::strtod(buffer, nullptr) == value;
    if (exact && (best.empty() || std::string(buffer).size() < best.size())) best = buffer;
  }
  return best;
}

TEST(FormatNumber, IsTheShortestPrintfSpellingThatReadsBack) {
  std::vector<double> values = {0.0,
                                -0.0,
                                0.7,
                                0.1,
                                1.0 / 3,
                                10,
                                100,
                                1e4,
                                1e5,
                                123456789012.0,
                                9007199254740993.0,
                                1e-5,
                                1e-4,
                                2.5e-300,
                                std::numeric_limits<double>::max(),
                                std::numeric_limits<double>::min(),
                                std::numeric_limits<double>::denorm_min(),
                                std::numeric_limits<double>::epsilon(),
                                std::numeric_limits<double>::infinity(),
                                -std::numeric_limits<double>::infinity(),
                                std::numeric_limits<double>::quiet_NaN()};
  std::mt19937_64 rng(20261126);
  for (int i = 0; i < 200000; ++i) {  // every bit pattern that is a finite double
    const uint64_t bits = rng();
    double x;
    std::memcpy(&x, &bits, sizeof x);
    if (std::isfinite(x)) values.push_back(x);
  }
  std::uniform_int_distribution<int> mantissa(-99999, 99999), exponent(-12, 12), digits(1, 5);
  for (int i = 0; i < 100000; ++i)  // typed decimals: "0.25", "-3.125e-7", "40000"
    values.push_back(std::strtod((std::to_string(mantissa(rng) % static_cast<int>(std::pow(10, digits(rng)))) +
                                  "e" + std::to_string(exponent(rng)))
                                     .c_str(),
                                 nullptr));
  for (int e = -20; e <= 20; ++e)
    for (double m : {1.0, 2.0, 9.0, 12.0, 99.0, 1234.0, 1.5, 150.0, 999999.0}) values.push_back(m * std::pow(10.0, e));
  // Powers of two (the gap below is half the gap above: the shortest form may round the other
  // way there) and powers of ten (where %g's rounding carries into the next exponent), with their
  // neighbours.
  std::vector<double> edges;
  for (int e = -1074; e <= 1023; ++e) edges.push_back(std::ldexp(1.0, e));
  for (int e = -30; e <= 30; ++e) edges.push_back(std::pow(10.0, e));
  for (double x : edges)
    for (double y : {x, std::nextafter(x, 0.0), std::nextafter(x, INFINITY), -x}) values.push_back(y);
  for (double x : values) ASSERT_EQ(delayspec::format_number(x), shortest_printf_spelling(x)) << x;
}

TEST(FormatText, ANoteOfAnyLengthKeepsItsLastWords) {
  // The notes of convergence and richardson are sentences with numbers; a fixed 240-byte buffer
  // once cut the longest short. 600 characters of text and the numbers at its end come out whole.
  const std::string long_text(600, 'x');
  const std::string format = long_text + " %.3g and %.0f levels";
  EXPECT_EQ(delayspec::format_text(format.c_str(), 0.125, 6), long_text + " 0.125 and 6 levels");
  EXPECT_EQ(delayspec::format_text("%g %g %g %g", 1, 2, 3, 4), "1 2 3 4");
}

}  // namespace
