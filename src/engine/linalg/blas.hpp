#pragma once
// The BLAS matrix product for the library's tall products (Krylov bases of n x ~40 at n up to
// 10^7): OpenBLAS's dgemm, with run-time chosen AVX2 kernels and threads, where Eigen's own
// product is compiled for the baseline x86-64 (SSE2) and runs on one core. Internal: not installed.
// OpenBLAS is loaded on first use (linear_algebra.hpp).
#include "engine/linalg/linear_algebra.hpp"

namespace delayspec {

// C = alpha op(A) op(B) + beta C (column-major; op = 'N' or 'T'); dimensions fit int (BLAS's).
inline void gemm(char ta, char tb, long m, long n, long k, double alpha, const double* A, long lda, const double* B,
                 long ldb, double beta, double* C, long ldc) {
  const int im = static_cast<int>(m), in = static_cast<int>(n), ik = static_cast<int>(k);
  const int ilda = static_cast<int>(lda), ildb = static_cast<int>(ldb), ildc = static_cast<int>(ldc);
  detail::lapack().dgemm(&ta, &tb, &im, &in, &ik, &alpha, A, &ilda, B, &ildb, &beta, C, &ildc);
}

}  // namespace delayspec
