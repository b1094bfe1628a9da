#pragma once
// Dense reference spectrum: all eigenvalues of a dense matrix, by Eigen's EigenSolver or
// LAPACK's dgeev (OpenBLAS). Used to check the Krylov solvers and to benchmark against;
// O(n^3) time and O(n^2) memory.
#include <complex>
#include <vector>

#include <Eigen/Core>

#include "delayspec/multipliers.hpp"

namespace delayspec {

enum class DenseBackend { eigen, lapack };

// All eigenvalues of A (square), in sort_by_modulus order (multipliers.hpp). Throws
// NumericalFailure when the QR algorithm does not converge, BadInput when A is not square or
// not finite.
std::vector<std::complex<double>> dense_eigenvalues(const Eigen::MatrixXd& A, DenseBackend backend);

}  // namespace delayspec
