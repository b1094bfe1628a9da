// The AVX2 + FMA path of the step-map kernels (kernel_dispatch.hpp): the same template as the
// portable path (block_kernel.hpp's block_steps), compiled in this file only with -mavx2 -mfma
// (CMakeLists.txt). Only the block kernel: one vector (single_steps) is a recurrence bound by the
// latency of P u0, and there FMA is slower, not faster (bench_apply, docs/benchmarks.md: 2.8 ns
// against 2.2 ns per step), so perform_op runs the portable code on every path.
//
// Why a tag of internal linkage: a template instantiated here and, with the same arguments, in a
// portable file would be one weak symbol with two machine codes, and the linker would keep either
// one (AVX2 code in the portable path crashes a CPU without AVX2). Avx2Target lives in an
// unnamed namespace, so every instantiation below is local to this file. The kernels touch only
// plain arrays and Eigen's coeff() (always inlined here); check after a change that this object
// defines no weak symbol: `nm -C CMakeFiles/delayspec.dir/src/block_kernel_avx2.cpp.o | grep ' [WVu] '`
// must print nothing.
#if (defined(__x86_64__) || defined(__i386__)) && !(defined(__AVX2__) && defined(__FMA__))
#error "src/block_kernel_avx2.cpp must be compiled with -mavx2 -mfma (CMakeLists.txt)"
#endif

#include "delayspec/detail/block_kernel.hpp"
#include "delayspec/detail/kernel_dispatch.hpp"

namespace delayspec::detail {

namespace {
struct Avx2Target {};
}  // namespace

void block_steps_avx2(const StepMap<1>* maps, long K, long M, long first_delayed, double theta, double* b, long k) {
  block_steps<1, Avx2Target>(maps, K, M, first_delayed, theta, b, k);
}
void block_steps_avx2(const StepMap<2>* maps, long K, long M, long first_delayed, double theta, double* b, long k) {
  block_steps<2, Avx2Target>(maps, K, M, first_delayed, theta, b, k);
}

}  // namespace delayspec::detail
