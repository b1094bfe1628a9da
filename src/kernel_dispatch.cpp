// Run-time choice of the kernel path (kernel_dispatch.hpp).
#include "delayspec/detail/kernel_dispatch.hpp"

#include <cstdlib>
#include <string>

#include "delayspec/errors.hpp"

namespace delayspec {

namespace {
bool cpu_has_avx2_fma() {
#if defined(__x86_64__) || defined(__i386__)
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
  return false;  // the AVX2 file is compiled without -mavx2 elsewhere; never chosen
#endif
}
}  // namespace

const char* kernel_path_name(KernelPath path) { return path == KernelPath::avx2 ? "avx2" : "baseline"; }

KernelPath choose_kernel_path(bool has_avx2_kernel) {
  const char* env = std::getenv("DELAYSPEC_KERNEL");
  const std::string wanted = env ? env : "";
  if (wanted == "baseline") return KernelPath::baseline;
  if (!wanted.empty() && wanted != "auto")
    throw BadInput("DELAYSPEC_KERNEL = '" + wanted + "': must be 'baseline' or 'auto' (or unset)");
  static const bool cpu_ok = cpu_has_avx2_fma();
  return has_avx2_kernel && cpu_ok ? KernelPath::avx2 : KernelPath::baseline;
}

}  // namespace delayspec
