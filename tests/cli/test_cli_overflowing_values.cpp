// Values at the ends of the double range (issue 31): before, tau = 1e300 was converted to long
// (undefined behaviour, seen as "tau/T = -9223372036854775808/1" in the message) and a range from
// -1e308 to 1e308 has a width to - from = inf, which made every point nan ("`a = -nan`"). Each is
// bad input (exit 2) whose message names the key, with no number built from an overflow.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cli_test_support.hpp"

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::contains;
using delayspec::testing::run;
using delayspec::testing::with_sets;

struct Overflow {
  const char* command;
  std::vector<std::string> sets;
  std::vector<std::string> named;  // what the message must contain (the keys)
};
void PrintTo(const Overflow& o, std::ostream* os) {
  *os << o.command;
  for (const auto& s : o.sets) *os << " " << s;
}

class OverflowingValue : public ::testing::TestWithParam<Overflow> {};

TEST_P(OverflowingValue, IsBadInputNamingTheKey) {
  const Overflow& o = GetParam();
  const CliResult r = run(with_sets({o.command, "--quiet"}, o.sets));
  EXPECT_EQ(r.status, 2) << r.err;
  for (const auto& part : o.named) EXPECT_TRUE(contains(r.err, part)) << part << " not in: " << r.err;
  for (const char* garbage : {"nan", "-9223372036854775808", "9223372036854775807", "inf ", "inf)"})
    EXPECT_FALSE(contains(r.err, garbage)) << garbage << " in: " << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

// clang-format off
INSTANTIATE_TEST_SUITE_P(Keys, OverflowingValue, ::testing::Values(
    // tau / T = 1e300: no integer ratio, and a history of 1e300 steps
    Overflow{"floquet", {"model=linear", "tau=1e300", "period=1"}, {"`tau = 1e+300`", "steps a history can hold"}},
    Overflow{"floquet", {"model=impact", "tau=1e300"}, {"`tau = 1e+300`"}},
    // tau / T = 1e15: an integer ratio, but beyond any N
    Overflow{"floquet", {"model=linear", "tau=1e15", "period=1"}, {"`tau = 1e+15`"}},
    Overflow{"floquet", {"model=linear", "tau=1e-300", "period=1"}, {"`N = 100`: too many steps", "tau = 1e-300"}},
    Overflow{"sweep", {"model=linear", "sweep_key=a", "sweep_from=-1e308", "sweep_to=1e308"},
             {"`sweep_from = -1e+308`", "`sweep_to = 1e+308`", "width of the range overflows"}},
    Overflow{"sweep", {"model=linear", "sweep_key=a", "sweep_from=1.7e308", "sweep_to=-1.7e308"},
             {"`sweep_from = 1.7e+308`", "`sweep_to = -1.7e+308`"}},
    Overflow{"chart", {"model=linear", "chart_x=a", "chart_y=b", "chart_x_range=-1e308,1e308"},
             {"`chart_x_range = -1e308,1e308`", "width of the range overflows"}},
    Overflow{"basin", {"model=linear", "basin_x=a", "basin_y=b", "basin_y_range=-1e308,1e308"},
             {"`basin_y_range = -1e308,1e308`"}},
    Overflow{"continue", {"model=linear", "continue_key=a", "continue_from=-1e308", "continue_to=1e308"},
             {"`continue_from = -1e+308`", "`continue_to = 1e+308`"}}));
// clang-format on

}  // namespace
