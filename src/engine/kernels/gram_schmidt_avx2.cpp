// The AVX2 + FMA path of the Gram-Schmidt chunk kernels (gram_schmidt_chunks.hpp says why and
// how the path is chosen): the same source as the portable path, compiled in this file only with
// -mavx2 -mfma (CMakeLists.txt). Its functions have internal linkage (an unnamed namespace in the
// header); check after a change that this object defines no weak symbol:
// `nm -C CMakeFiles/delayspec.dir/src/gram_schmidt_avx2.cpp.o | grep ' [WVu] '` must print nothing.
#if (defined(__x86_64__) || defined(__i386__)) && !(defined(__AVX2__) && defined(__FMA__))
#error "src/engine/kernels/gram_schmidt_avx2.cpp must be compiled with -mavx2 -mfma (CMakeLists.txt)"
#endif

#include "engine/kernels/gram_schmidt_chunks.hpp"

namespace delayspec::detail {

const GramSchmidtChunkKernels& gram_schmidt_chunks_avx2() { return kChunkKernels; }

}  // namespace delayspec::detail
