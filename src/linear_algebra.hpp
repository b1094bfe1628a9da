#pragma once
// The entry points of the linear-algebra libraries the library calls: BLAS dgemm and LAPACK
// dgeev / dgees (OpenBLAS), ARPACK-ng's dnaupd / dneupd, SuiteSparse UMFPACK. Internal: not
// installed (include/delayspec/linear_algebra_libraries.hpp is the public side).
//
// Why through a table: the libraries are not linked but loaded with dlopen on first use
// (src/linear_algebra.cpp). Linked, they cost every process 2 ms of its start-up, whether or not
// it solves anything (the dynamic loader binds OpenBLAS's ~14000 kernel-table relocations before
// main: docs/benchmarks.md, "Eighth sitting"); loaded on first use, `--version`, `lyapunov` and
// the others that need none of them do not pay it.
#include <arpack/arpackdef.h>
#include <umfpack.h>

namespace delayspec::detail {

struct LinearAlgebra {
  // BLAS / LAPACK, Fortran calling convention (column-major, every argument by pointer)
  using Dgemm = void(const char* transa, const char* transb, const int* m, const int* n, const int* k,
                     const double* alpha, const double* a, const int* lda, const double* b, const int* ldb,
                     const double* beta, double* c, const int* ldc);
  using Dgeev = void(const char* jobvl, const char* jobvr, const int* n, double* a, const int* lda, double* wr,
                     double* wi, double* vl, const int* ldvl, double* vr, const int* ldvr, double* work,
                     const int* lwork, int* info);
  using Dgees = void(const char* jobvs, const char* sort, int (*select)(const double*, const double*), const int* n,
                     double* a, const int* lda, int* sdim, double* wr, double* wi, double* vs, const int* ldvs,
                     double* work, const int* lwork, int* bwork, int* info);
  // ARPACK-ng's ISO_C_BINDING entry points (arpack/arpack.h declares them with C99 `_Complex`
  // prototypes that are not C++)
  using DnaupdC = void(a_int* ido, char const* bmat, a_int n, char const* which, a_int nev, double tol, double* resid,
                       a_int ncv, double* v, a_int ldv, a_int* iparam, a_int* ipntr, double* workd, double* workl,
                       a_int lworkl, a_int* info);
  using DneupdC = void(a_int rvec, char const* howmny, a_int const* select, double* dr, double* di, double* z,
                       a_int ldz, double sigmar, double sigmai, double* workev, char const* bmat, a_int n,
                       char const* which, a_int nev, double tol, double* resid, a_int ncv, double* v, a_int ldv,
                       a_int* iparam, a_int* ipntr, double* workd, double* workl, a_int lworkl, a_int* info);

  Dgemm* dgemm = nullptr;
  Dgeev* dgeev = nullptr;
  Dgees* dgees = nullptr;
  DnaupdC* dnaupd_c = nullptr;
  DneupdC* dneupd_c = nullptr;
  // decltype of umfpack.h's declarations (unevaluated: no reference to the symbols)
  decltype(&::umfpack_di_defaults) umfpack_di_defaults = nullptr;
  decltype(&::umfpack_di_symbolic) umfpack_di_symbolic = nullptr;
  decltype(&::umfpack_di_numeric) umfpack_di_numeric = nullptr;
  decltype(&::umfpack_di_solve) umfpack_di_solve = nullptr;
  decltype(&::umfpack_di_free_symbolic) umfpack_di_free_symbolic = nullptr;
  decltype(&::umfpack_di_free_numeric) umfpack_di_free_numeric = nullptr;
};

// The table, the libraries loaded by the first call (thread-safe; later calls only return it).
// BadInput naming the library and the loader's reason when one cannot be loaded or lacks an
// entry point, on every call.
const LinearAlgebra& linear_algebra();

}  // namespace delayspec::detail
