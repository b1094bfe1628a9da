#include "delayspec/memory_budget.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>

#include "delayspec/errors.hpp"

namespace delayspec {

namespace {

// The process's mapped address space now (VmSize of /proc/self/status), 0 if unknown.
double mapped_bytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmSize:", 0) == 0) return 1024.0 * std::strtod(line.c_str() + 7, nullptr);
  return 0;
}

std::string gigabytes(double bytes) {
  char text[64];
  std::snprintf(text, sizeof text, "%.3g GB", bytes / 1e9);
  return text;
}

}  // namespace

double memory_budget_bytes() {
  double budget = std::numeric_limits<double>::infinity();
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  if (pages > 0 && page > 0) budget = static_cast<double>(pages) * static_cast<double>(page);
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    budget = std::min(budget, static_cast<double>(limit.rlim_cur) - mapped_bytes());
  return std::max(budget, 1.0);
}

void require_memory(double bytes, const std::string& what, const std::string& how, double budget) {
  if (!(bytes > budget)) return;
  throw BadInput(what + " needs at least " + gigabytes(bytes) + " (" + how + "), more than the " + gigabytes(budget) +
                 " this process may use (the smaller of the physical memory and the address space left under "
                 "ulimit -v)");
}

void require_memory(double bytes, const std::string& what, const std::string& how) {
  require_memory(bytes, what, how, memory_budget_bytes());
}

}  // namespace delayspec
