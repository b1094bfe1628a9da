#pragma once
// Floquet multipliers: the largest-modulus eigenvalues of a Monodromy (design.md 1.6).
// One entry point, several backends on the same operator:
//   dense_eigen / dense_lapack: form the n x n matrix, all eigenvalues (reference, O(n^3));
//   spectra / arpack: Krylov on the matrix-free operator (see the Krylov extension).
#include <complex>
#include <string>
#include <vector>

#include "delayspec/monodromy.hpp"

namespace delayspec {

enum class FloquetSolver { spectra, arpack, dense_eigen, dense_lapack };

// "spectra", "arpack", "dense" (= dense_lapack), "dense-eigen", "dense-lapack"; BadInput otherwise.
FloquetSolver parse_floquet_solver(const std::string& name);
std::string to_string(FloquetSolver solver);

struct FloquetOptions {
  int nev = 6;                              // multipliers wanted
  FloquetSolver solver = FloquetSolver::spectra;
};

struct FloquetResult {
  std::vector<std::complex<double>> multipliers;  // sorted by modulus, largest first
  std::string solver;                            // backend that produced them
  long operator_applications = 0;                // single-vector applications of the operator
  double seconds = 0;                            // wall time of the eigen-solve (incl. assembly)
  std::string note;                              // e.g. why a Krylov request went dense
};

// The nev leading multipliers. BadInput: nev < 1 or nev > n. NumericalFailure: no convergence.
template <int D>
FloquetResult floquet_multipliers(const Monodromy<D>& op, const FloquetOptions& options);

extern template FloquetResult floquet_multipliers<1>(const Monodromy<1>&, const FloquetOptions&);
extern template FloquetResult floquet_multipliers<2>(const Monodromy<2>&, const FloquetOptions&);

}  // namespace delayspec
