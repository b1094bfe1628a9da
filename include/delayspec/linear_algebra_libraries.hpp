#pragma once
// The linear-algebra libraries (OpenBLAS's BLAS and LAPACK, ARPACK-ng, SuiteSparse UMFPACK) are
// not linked into libdelayspec: the library loads them with dlopen the first time a solver needs
// one (dense LAPACK, the block Krylov-Schur's dgemm and dgees, ARPACK, the sparse LU of Newton's
// method), so a process that needs none of them (`--version`, `lyapunov`, `simulate`) does not
// pay their 2 ms of loading (docs/design.md, "Modules loaded on first use").

namespace delayspec {

// Loads the libraries now (nothing after the first time, from any thread); BadInput naming the
// library and the loader's reason when one cannot be loaded. The solvers call it themselves:
// a caller needs it only to load them at a time of its choosing.
void load_linear_algebra();

}  // namespace delayspec
