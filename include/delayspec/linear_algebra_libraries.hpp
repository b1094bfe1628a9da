#pragma once
// The linear-algebra libraries (OpenBLAS's BLAS and LAPACK, ARPACK-ng, SuiteSparse UMFPACK) are
// not linked into libdelayspec: the library loads each with dlopen the first time a solver needs
// it (OpenBLAS: dense LAPACK, the block Krylov-Schur's dgees and the Krylov solvers' dgemm;
// ARPACK; UMFPACK: the sparse LU of Newton's method), so a process that needs none of them (`--version`, `lyapunov`,
// `simulate`) does not pay their 2.5 ms of loading (docs/design.md, "Modules loaded on first use").

namespace delayspec {

// Loads all three now (nothing after the first time, from any thread); BadInput naming the
// library and the loader's reason when one cannot be loaded. The solvers load what they need
// themselves: a caller needs this only to load them at a time of its choosing.
void load_linear_algebra();

}  // namespace delayspec
