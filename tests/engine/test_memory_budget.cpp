// Sizes bounded before allocation (memory_budget.hpp): the budget is the machine's memory at most,
// and an estimate above it is BadInput naming what asked for it.
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <unistd.h>

#include <string>

#include "delayspec/errors.hpp"
#include "delayspec/memory_budget.hpp"

using delayspec::BadInput;

TEST(MemoryBudget, IsPositiveAndAtMostThePhysicalMemory) {
  const double physical = static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGESIZE));
  const double budget = delayspec::memory_budget_bytes();
  EXPECT_GT(budget, 0);
  EXPECT_LE(budget, physical);
}

TEST(MemoryBudget, AnEstimateAboveTheBudgetNamesWhatAskedAndHow) {
  EXPECT_NO_THROW(delayspec::require_memory(1e9, "`N = 5`", "two histories", 2e9));
  try {
    delayspec::require_memory(3e9, "`N = 5`", "two histories", 2e9);
    FAIL() << "no BadInput";
  } catch (const BadInput& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("`N = 5` needs at least 3 GB (two histories), more than the 2 GB"), std::string::npos)
        << what;
  }
}
