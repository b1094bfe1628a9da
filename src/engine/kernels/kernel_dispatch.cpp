// Run-time choice of the kernel path (kernel_dispatch.hpp).
#include "delayspec/detail/kernel_dispatch.hpp"

#include <algorithm>
#include <cstdlib>
#include <iterator>
#include <string>

#include "delayspec/errors.hpp"

namespace delayspec {

namespace {
// The widest path this CPU runs.
KernelPath cpu_widest_path() {
#if defined(__x86_64__) || defined(__i386__)
  if (!(__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))) return KernelPath::baseline;
  return __builtin_cpu_supports("avx512f") ? KernelPath::avx512 : KernelPath::avx2;
#else
  return KernelPath::baseline;  // the wide files are compiled without their flags elsewhere; never chosen
#endif
}
}  // namespace

const char* kernel_path_name(KernelPath path) {
  switch (path) {
    case KernelPath::avx512: return "avx512";
    case KernelPath::avx2: return "avx2";
    case KernelPath::baseline: break;
  }
  return "baseline";
}

KernelPath choose_kernel_path(KernelPath widest) {
  static const KernelPath cpu = cpu_widest_path();
  const char* env = std::getenv("DELAYSPEC_KERNEL");
  const std::string wanted = env ? env : "";
  KernelPath path = cpu;
  if (!wanted.empty() && wanted != "auto") {
    const KernelPath named[] = {KernelPath::baseline, KernelPath::avx2, KernelPath::avx512};
    const auto it =
        std::find_if(std::begin(named), std::end(named), [&](KernelPath p) { return wanted == kernel_path_name(p); });
    if (it == std::end(named))
      throw BadInput("DELAYSPEC_KERNEL = '" + wanted + "': must be 'baseline', 'avx2', 'avx512' or 'auto' (or unset)");
    if (*it > cpu)
      throw BadInput("DELAYSPEC_KERNEL = '" + wanted + "': this CPU runs at most the '" + kernel_path_name(cpu) +
                     "' path");
    path = *it;
  }
  return std::min(path, widest);
}

}  // namespace delayspec
