#pragma once
// LinearOperator: what the eigensolvers need of an operator, whatever its state dimension d:
// y = A x for one vector or a block of vectors, its size, and the dense matrix for the dense
// reference. Monodromy<D> is one (monodromy.hpp); the Krylov backends and floquet_multipliers()
// take this interface, so they are compiled once in the library and work for a model of any d
// (one virtual call per application, against O(n) work inside it).
//
// Usable as a Spectra operator: Scalar, rows(), cols(), perform_op(const double*, double*).
#include <Eigen/Core>

namespace delayspec {

class LinearOperator {
 public:
  using Scalar = double;
  virtual ~LinearOperator() = default;

  virtual Eigen::Index rows() const = 0;
  Eigen::Index cols() const { return rows(); }
  // y = A x, both of length n, unchecked (Spectra's interface).
  virtual void perform_op(const double* x, double* y) const = 0;
  // Y = A X for an n x k block (BadInput when X has not n rows).
  virtual void apply_block(const Eigen::MatrixXd& X, Eigen::MatrixXd& Y) const = 0;
  // The dense n x n matrix (reference only).
  virtual Eigen::MatrixXd to_dense() const = 0;
  // Single-vector applications so far (a block of k counts k).
  virtual long applications() const = 0;

 protected:
  LinearOperator() = default;
  LinearOperator(const LinearOperator&) = default;
  LinearOperator& operator=(const LinearOperator&) = default;
};

}  // namespace delayspec
