#include "scene/output/memory_probe.hpp"

#include <malloc.h>

#include <fstream>
#include <string>

namespace delayspec::cli {

namespace {

// A "Vm...:  123 kB" line of /proc/self/status, in bytes; -1 when absent.
long status_bytes(const std::string& field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind(field + ":", 0) == 0) return std::stol(line.substr(field.size() + 1)) * 1024;
  return -1;
}

}  // namespace

MemoryProbe::MemoryProbe() {
  malloc_trim(0);
  std::ofstream clear("/proc/self/clear_refs");
  if (!clear) return;
  clear << "5";
  clear.close();
  if (clear.fail()) return;
  baseline_ = status_bytes("VmRSS");
  available_ = baseline_ >= 0;
}

long MemoryProbe::peak_bytes() const {
  if (!available_) return -1;
  const long peak = status_bytes("VmHWM");
  return peak < 0 ? -1 : std::max(0L, peak - baseline_);
}

}  // namespace delayspec::cli
