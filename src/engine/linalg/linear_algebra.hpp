#pragma once
// The entry points of the linear-algebra libraries the library calls: BLAS dgemm and LAPACK
// dgeev / dgees / zgesvd (OpenBLAS), ARPACK-ng's dnaupd / dneupd, SuiteSparse UMFPACK's umfpack_di_*. Internal: not
// installed (include/delayspec/linear_algebra_libraries.hpp is the public side).
//
// Why through a table: the libraries are not linked but loaded with dlopen on first use
// (src/engine/linalg/linear_algebra.cpp). Linked, they cost every process 2 ms of its start-up, whether or not
// it solves anything (the dynamic loader binds OpenBLAS's ~14000 kernel-table relocations before
// main: docs/benchmarks.md, "Eighth sitting"); loaded on first use, `--version`, `lyapunov` and
// the others that need none of them do not pay it.
#include <complex>

#include <arpack/arpackdef.h>
#include <umfpack.h>

namespace delayspec::detail {

// OpenBLAS: BLAS and LAPACK, Fortran calling convention (column-major, every argument by pointer)
struct Lapack {
  using Dgemm = void(const char* transa, const char* transb, const int* m, const int* n, const int* k,
                     const double* alpha, const double* a, const int* lda, const double* b, const int* ldb,
                     const double* beta, double* c, const int* ldc);
  using Dgeev = void(const char* jobvl, const char* jobvr, const int* n, double* a, const int* lda, double* wr,
                     double* wi, double* vl, const int* ldvl, double* vr, const int* ldvr, double* work,
                     const int* lwork, int* info);
  using Dgees = void(const char* jobvs, const char* sort, int (*select)(const double*, const double*), const int* n,
                     double* a, const int* lda, int* sdim, double* wr, double* wi, double* vs, const int* ldvs,
                     double* work, const int* lwork, int* bwork, int* info);
  // COMPLEX*16 is laid out as std::complex<double> (two doubles, real first)
  using Zgesvd = void(const char* jobu, const char* jobvt, const int* m, const int* n, std::complex<double>* a,
                      const int* lda, double* s, std::complex<double>* u, const int* ldu, std::complex<double>* vt,
                      const int* ldvt, std::complex<double>* work, const int* lwork, double* rwork, int* info);
  Dgemm* dgemm = nullptr;
  Dgeev* dgeev = nullptr;
  Dgees* dgees = nullptr;
  Zgesvd* zgesvd = nullptr;
};

// ARPACK-ng's ISO_C_BINDING entry points (arpack/arpack.h declares them with C99 `_Complex`
// prototypes that are not C++)
struct Arpack {
  using DnaupdC = void(a_int* ido, char const* bmat, a_int n, char const* which, a_int nev, double tol, double* resid,
                       a_int ncv, double* v, a_int ldv, a_int* iparam, a_int* ipntr, double* workd, double* workl,
                       a_int lworkl, a_int* info);
  using DneupdC = void(a_int rvec, char const* howmny, a_int const* select, double* dr, double* di, double* z,
                       a_int ldz, double sigmar, double sigmai, double* workev, char const* bmat, a_int n,
                       char const* which, a_int nev, double tol, double* resid, a_int ncv, double* v, a_int ldv,
                       a_int* iparam, a_int* ipntr, double* workd, double* workl, a_int lworkl, a_int* info);
  DnaupdC* dnaupd_c = nullptr;
  DneupdC* dneupd_c = nullptr;
};

// SuiteSparse UMFPACK: decltype of umfpack.h's declarations (unevaluated: no reference to the symbols)
struct Umfpack {
  decltype(&::umfpack_di_defaults) di_defaults = nullptr;
  decltype(&::umfpack_di_symbolic) di_symbolic = nullptr;
  decltype(&::umfpack_di_numeric) di_numeric = nullptr;
  decltype(&::umfpack_di_solve) di_solve = nullptr;
  decltype(&::umfpack_di_free_symbolic) di_free_symbolic = nullptr;
  decltype(&::umfpack_di_free_numeric) di_free_numeric = nullptr;
};

// Each table, its library (and what that needs) loaded by the first call (thread-safe; later
// calls only return it). Each library on its own: the block Krylov-Schur and Spectra need only
// OpenBLAS, and ARPACK and UMFPACK with theirs (libgfortran, LAPACK's Fortran interface,
// CHOLMOD, METIS) are 0.8 ms more (docs/benchmarks.md, "Eighth sitting"). BadInput naming the library and the
// loader's reason when it cannot be loaded or lacks an entry point, on every call.
const Lapack& lapack();
const Arpack& arpack();
const Umfpack& umfpack();

}  // namespace delayspec::detail
