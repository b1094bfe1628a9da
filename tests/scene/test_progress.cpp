// Progress: silent when quiet or short, periodic lines otherwise, a bar when asked, counts
// exactly under concurrent add() from several threads.
#include <gtest/gtest.h>

#include <sstream>
#include <thread>
#include <vector>

#include "scene/output/progress.hpp"

using delayspec::cli::format_duration;
using delayspec::cli::Progress;
using delayspec::cli::ProgressOptions;

namespace {

ProgressOptions lines_every(double seconds) {
  ProgressOptions o;
  o.style = ProgressOptions::Style::lines;
  o.line_interval_seconds = seconds;
  return o;
}

}  // namespace

TEST(Progress, QuietPrintsNothing) {
  std::ostringstream err;
  {
    Progress p(err, "sweep", 10, /*quiet=*/true, lines_every(0));
    for (int i = 0; i < 10; ++i) p.add();
  }
  EXPECT_TRUE(err.str().empty()) << err.str();
}

TEST(Progress, ShortWorkPrintsNothing) {
  std::ostringstream err;
  {
    Progress p(err, "sweep", 10, false, lines_every(3600));
    for (int i = 0; i < 10; ++i) p.add();
  }
  EXPECT_TRUE(err.str().empty()) << err.str();
}

TEST(Progress, LinesCarryCountPercentRateEtaAndAClosingLine) {
  std::ostringstream err;
  Progress p(err, "sweep", 4, false, lines_every(0));  // interval 0: report on every add
  p.add();
  p.add();
  const std::string after_two = err.str();
  EXPECT_NE(after_two.find("sweep: 1/4 (25%), "), std::string::npos) << after_two;
  EXPECT_NE(after_two.find("sweep: 2/4 (50%), "), std::string::npos) << after_two;
  EXPECT_NE(after_two.find("/s, ETA "), std::string::npos) << after_two;
  p.add(2);
  p.finish();
  p.finish();  // idempotent
  const std::string all = err.str();
  EXPECT_NE(all.find("sweep: 4/4 done in "), std::string::npos) << all;
  EXPECT_EQ(all.find("done in"), all.rfind("done in")) << "one closing line: " << all;
}

TEST(Progress, BarRedrawsInPlaceAndEndsWithNewline) {
  std::ostringstream err;
  ProgressOptions o;
  o.style = ProgressOptions::Style::bar;
  o.bar_interval_seconds = 0;
  o.bar_width = 10;
  Progress p(err, "grid", 10, false, o);
  for (int i = 0; i < 5; ++i) p.add();
  EXPECT_NE(err.str().find("\rgrid [#####.....]  5/10  "), std::string::npos) << err.str();
  p.add(5);
  p.finish();
  EXPECT_NE(err.str().find("[##########]  10/10"), std::string::npos) << err.str();
  EXPECT_EQ(err.str().back(), '\n');
}

TEST(Progress, UnknownTotalHasNoEta) {
  std::ostringstream err;
  Progress p(err, "periods", 0, false, lines_every(0));
  p.add(7);
  EXPECT_NE(err.str().find("periods: 7, "), std::string::npos) << err.str();
  EXPECT_EQ(err.str().find("ETA"), std::string::npos) << err.str();
}

TEST(Progress, ConcurrentAddsAreCountedExactly) {
  std::ostringstream err;
  Progress p(err, "parallel", 4 * 20000, false, lines_every(0.001));
  std::vector<std::thread> workers;
  for (int t = 0; t < 4; ++t)
    workers.emplace_back([&] {
      for (int i = 0; i < 20000; ++i) p.add();
    });
  for (auto& w : workers) w.join();
  EXPECT_EQ(p.count(), 4 * 20000);
}

TEST(Progress, DurationFormatting) {
  EXPECT_EQ(format_duration(3.25), "3.2 s");
  EXPECT_EQ(format_duration(42), "42 s");
  EXPECT_EQ(format_duration(200), "3 min 20 s");
  EXPECT_EQ(format_duration(3900), "1 h 05 min");
}
