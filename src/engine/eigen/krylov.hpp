#pragma once
// Internal interface between floquet.cpp and the Krylov backends (krylov_spectra.cpp,
// krylov_arpack.cpp, krylov_block.cpp). Not installed: users call floquet_multipliers().
#include <complex>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "delayspec/linear_operator.hpp"

namespace delayspec::krylov {

// Validated settings (floquet.cpp checks them): 1 <= nev <= n - 2, nev + 2 <= ncv <= n,
// tolerance > 0, max_iterations >= 1.
struct Settings {
  int nev = 0;
  int ncv = 0;
  double tolerance = 0;
  int max_iterations = 0;
  double scale = 1;    // Spectra only: the solver works on M / scale (a power of two), see krylov_spectra.cpp
  int block_size = 1;  // block only: vectors per block (krylov_block.cpp)
};

// Converged Ritz pairs, each real eigenvalue and each complex-conjugate pair once.
// values[i] has imag >= 0; its eigenvector is vectors.col(column[i]) when real, and
// vectors.col(column[i]) + i vectors.col(column[i] + 1) when complex (the conjugate pair's
// vector is the conjugate). At least the nev leading values are present (a pair split by nev
// is completed).
struct RitzPairs {
  std::vector<std::complex<double>> values;
  std::vector<long> column;
  Eigen::MatrixXd vectors;  // n x (columns used); may hold unused columns (ARPACK: its basis)
  int converged = 0;        // as reported by the backend (ARPACK: iparam(5))
  int iterations = 0;       // Arnoldi iterations (1 + restarts)
};

// Both throw NumericalFailure when the backend does not converge within max_iterations or
// reports an error; the message names iterations, converged count and residual estimate.
// start has n entries (the same vector for both backends).
RitzPairs spectra_ritz_pairs(const LinearOperator& op, const Settings& settings, const Eigen::VectorXd& start);
RitzPairs arpack_ritz_pairs(const LinearOperator& op, const Settings& settings, const Eigen::VectorXd& start);
RitzPairs block_ritz_pairs(const LinearOperator& op, const Settings& settings, const Eigen::VectorXd& start);

// The RitzPairs of the leading Ritz values `theta` (sorted by modulus) with coefficient vectors
// `y` (Ritz vector = V y) in the orthonormal basis V: representatives (real values, and each
// complex pair once with imag > 0; a pair split by the list is completed from its conjugate) and
// their vectors in real form (one column per real value, Re and Im columns per pair).
// converged and iterations are left for the caller.
RitzPairs ritz_pairs_in_basis(const std::vector<std::complex<double>>& theta, const std::vector<Eigen::VectorXcd>& y,
                              const Eigen::Ref<const Eigen::MatrixXd>& V);

// Largest relative Ritz estimate est_i / max(|theta_i|, eps^(2/3)) over the nev largest-modulus
// Ritz values theta (the quantity both backends compare with the tolerance).
double largest_relative_estimate(const std::vector<std::complex<double>>& theta, const std::vector<double>& estimate,
                                 int nev);

}  // namespace delayspec::krylov
