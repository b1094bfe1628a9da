#pragma once
// SparseLU: a sparse LU factorisation (SuiteSparse UMFPACK, umfpack_di_*) of a square matrix,
// factored once and solved many times. RAII: the symbolic and numeric objects are freed by
// the destructor; movable, not copyable. umfpack.h stays out of this header (the library loads
// UMFPACK on first use: linear_algebra_libraries.hpp).
//
// Errors: BadInput for a non-square or empty matrix or a right-hand side of the wrong size;
// NumericalFailure when UMFPACK reports a singular matrix (the message carries UMFPACK's
// reciprocal condition estimate) or any other non-OK status (named with its code).
//
//   Eigen::SparseMatrix<double> J = ...;
//   SparseLU lu(J);
//   Eigen::VectorXd x = lu.solve(b);   // J x = b
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace delayspec {

class SparseLU {
 public:
  // Factors A (copied into compressed column form). Throws as described above.
  explicit SparseLU(const Eigen::SparseMatrix<double>& A);
  ~SparseLU();
  SparseLU(SparseLU&& other) noexcept;
  SparseLU& operator=(SparseLU&& other) noexcept;
  SparseLU(const SparseLU&) = delete;
  SparseLU& operator=(const SparseLU&) = delete;

  // x with A x = b (UMFPACK's default iterative refinement included).
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;

  long size() const { return n_; }
  // UMFPACK's estimate of the reciprocal condition number (1-norm) from the numeric factorisation.
  double reciprocal_condition() const { return rcond_; }
  // Nonzeros of the L and U factors (fill-in included).
  long factor_nonzeros() const { return factor_nonzeros_; }

 private:
  void release() noexcept;

  long n_ = 0;
  std::vector<int> column_starts_, row_indices_;
  std::vector<double> values_;
  void* symbolic_ = nullptr;
  void* numeric_ = nullptr;
  double rcond_ = 0;
  long factor_nonzeros_ = 0;
};

// The bordered matrix [A c; r^T corner] (n + 1 square), compressed for the LU: a Newton system
// with one more unknown (a parameter, a period) and one more equation (a constraint).
Eigen::SparseMatrix<double> bordered_matrix(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& c,
                                            const Eigen::VectorXd& r, double corner);

}  // namespace delayspec
