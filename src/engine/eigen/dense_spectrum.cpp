#include "delayspec/dense_spectrum.hpp"

#include <algorithm>
#include <string>

#include <Eigen/Eigenvalues>

#include "delayspec/errors.hpp"
#include "engine/linalg/linear_algebra.hpp"

namespace delayspec {

namespace {

std::vector<std::complex<double>> eigen_backend(const Eigen::MatrixXd& A) {
  Eigen::EigenSolver<Eigen::MatrixXd> solver(A, /*computeEigenvectors=*/false);
  if (solver.info() != Eigen::Success)
    throw NumericalFailure(
        "dense eigenvalues (Eigen): the QR algorithm did not converge (n = " + std::to_string(A.rows()) + ")");
  const auto& ev = solver.eigenvalues();
  return {ev.data(), ev.data() + ev.size()};
}

std::vector<std::complex<double>> lapack_backend(const Eigen::MatrixXd& A) {
  const int n = static_cast<int>(A.rows());
  Eigen::MatrixXd a = A;  // dgeev overwrites its input
  std::vector<double> wr(n), wi(n);
  int info = 0, lwork = -1, one = 1;
  double query = 0, dummy = 0;
  const auto dgeev = detail::lapack().dgeev;
  dgeev("N", "N", &n, a.data(), &n, wr.data(), wi.data(), &dummy, &one, &dummy, &one, &query, &lwork, &info);
  lwork = std::max(1, static_cast<int>(query));
  std::vector<double> work(lwork);
  dgeev("N", "N", &n, a.data(), &n, wr.data(), wi.data(), &dummy, &one, &dummy, &one, work.data(), &lwork, &info);
  if (info != 0)
    throw NumericalFailure("dense eigenvalues (LAPACK dgeev): info = " + std::to_string(info) +
                           (info > 0 ? " (QR algorithm failed to converge)" : " (illegal argument)"));
  std::vector<std::complex<double>> values(n);
  for (int i = 0; i < n; ++i) values[i] = {wr[i], wi[i]};
  return values;
}

}  // namespace

std::vector<std::complex<double>> dense_eigenvalues(const Eigen::MatrixXd& A, DenseBackend backend) {
  if (A.rows() != A.cols())
    throw BadInput("dense_eigenvalues: matrix is " + std::to_string(A.rows()) + " x " + std::to_string(A.cols()) +
                   ", must be square");
  if (!A.allFinite()) throw BadInput("dense_eigenvalues: matrix has non-finite entries");
  if (A.rows() == 0) return {};
  auto values = backend == DenseBackend::eigen ? eigen_backend(A) : lapack_backend(A);
  sort_by_modulus(values);
  return values;
}

}  // namespace delayspec
