#pragma once
// Dense reference spectrum: all eigenvalues of a dense matrix, by Eigen's EigenSolver or
// LAPACK's dgeev (OpenBLAS). Used to check the Krylov solvers and to benchmark against;
// O(n^3) time and O(n^2) memory.
#include <complex>
#include <vector>

#include <Eigen/Core>

namespace delayspec {

enum class DenseBackend { eigen, lapack };

// All eigenvalues of A (square), sorted by modulus, largest first (ties: by real part, then
// imaginary part descending, so complex pairs come + then -). Throws NumericalFailure when the
// QR algorithm does not converge, BadInput when A is not square or not finite.
std::vector<std::complex<double>> dense_eigenvalues(const Eigen::MatrixXd& A, DenseBackend backend);

// Sorts eigenvalues by modulus, largest first, with the tie rule above.
void sort_by_modulus(std::vector<std::complex<double>>& values);

}  // namespace delayspec
