// Spectra backend of floquet_multipliers(): GenEigsSolver (implicitly restarted Arnoldi) with
// the Monodromy itself as the operator (its perform_op is Spectra's duck type).
// GCC 12 reports a false -Wuse-after-free inside Eigen's aligned_free when it inlines Spectra's
// UpperHessenbergEigen (a known GCC 12 false positive on Eigen temporaries); nothing here frees twice.
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 12
#pragma GCC diagnostic ignored "-Wuse-after-free"
#endif
#include <Spectra/GenEigsSolver.h>
#include <Spectra/Util/Version.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "delayspec/errors.hpp"
#include "engine/eigen/krylov.hpp"

namespace delayspec::krylov {

namespace {

// Spectra 1.0.1 decides that the Arnoldi residual f is zero (an invariant subspace: restart from a
// fresh random vector) with ABSOLUTE thresholds (LinAlg/Arnoldi.h: max |f_i| < eps after the first
// step, |f| < eps sqrt(n) later). For an operator of norm >> 1, e.g. a strongly unstable or
// rank-deficient monodromy (x' = 5 x: M is rank one with mu_1 = 149), the round-off left in f is
// far above them: the basis grows from noise, H gets a highly non-normal noise block, and its
// eigenvalues are spurious Ritz values whose own estimates |f| |e_m^T y| look converged
// (issue 13: -223 + 441i returned for 149.03, true residual 1.14). The residual gate of
// floquet.cpp catches that and retries with Settings::scale > 1: Spectra then works on M / scale,
// which puts its thresholds at the operator's round-off level; dividing by a power of two is exact,
// so the Ritz values are mu / scale to the last bit. (Not on the first attempt: for a large n the
// scaled thresholds are looser than needed, eps n |M x| / |x|, and every ordinary case passes
// the gate unscaled.)
class ScaledMonodromy {
 public:
  using Scalar = double;
  ScaledMonodromy(const LinearOperator& op, double scale) : op_(op), inverse_scale_(1 / scale) {}
  Eigen::Index rows() const { return op_.rows(); }
  Eigen::Index cols() const { return op_.cols(); }
  // y = M x / scale
  void perform_op(const double* x, double* y) const {
    op_.perform_op(x, y);
    if (inverse_scale_ != 1) Eigen::Map<Eigen::VectorXd>(y, op_.rows()) *= inverse_scale_;
  }

 private:
  const LinearOperator& op_;
  double inverse_scale_;
};

// GenEigsSolver plus read access to what Spectra keeps protected: the Arnoldi basis V, the
// Ritz coefficient vectors y (Ritz vector = V y) and the residual estimates |f| |e_m^T y|.
// Protected members are not Spectra's interface: this class is pinned to the version it was
// written and tested against (Debian's libspectra-dev 1.0.1; the Krylov tests check the pairs it
// returns against their true residuals and the dense spectrum). Another version stops the build
// here: re-read GenEigsSolver / EigsBase for m_fac, m_ritz_val, m_ritz_vec, m_ritz_est, m_nev.
static_assert(SPECTRA_MAJOR_VERSION == 1 && SPECTRA_MINOR_VERSION == 0 && SPECTRA_PATCH_VERSION == 1,
              "krylov_spectra.cpp reads Spectra 1.0.1's protected members: check them for this version");
class SpectraSolver : public Spectra::GenEigsSolver<const ScaledMonodromy> {
  using Base = Spectra::GenEigsSolver<const ScaledMonodromy>;

 public:
  SpectraSolver(const ScaledMonodromy& op, int nev, int ncv) : Base(op, nev, ncv) {}

  const Eigen::MatrixXd& basis() const { return this->m_fac.matrix_V(); }
  // The nev wanted Ritz values and their coefficient vectors (ncv x nev), sorted by modulus.
  std::complex<double> value(int i) const { return this->m_ritz_val[i]; }
  Eigen::VectorXcd coefficients(int i) const { return this->m_ritz_vec.col(i); }

  // Largest relative residual estimate of the wanted Ritz values (for the failure message).
  // After compute() only the first nev Ritz values are sorted and valid; they are in the same
  // (largest-modulus) order as the estimates, conjugate pairs having equal estimates.
  double largest_estimate() const {
    std::vector<std::complex<double>> theta;
    std::vector<double> est;
    for (Eigen::Index i = 0; i < this->m_nev; ++i) {
      theta.push_back(this->m_ritz_val[i]);
      est.push_back(std::abs(this->m_ritz_est[i]) * this->m_fac.f_norm());
    }
    return largest_relative_estimate(theta, est, static_cast<int>(this->m_nev));
  }
};

}  // namespace

RitzPairs spectra_ritz_pairs(const LinearOperator& op, const Settings& s, const Eigen::VectorXd& start) {
  const double scale = s.scale;
  const ScaledMonodromy scaled(op, scale);
  SpectraSolver solver(scaled, s.nev, s.ncv);
  solver.init(start.data());  // Spectra starts from M * start (forces the vector into M's range)
  Eigen::Index nconv = 0;
  try {
    nconv =
        solver.compute(Spectra::SortRule::LargestMagn, s.max_iterations, s.tolerance, Spectra::SortRule::LargestMagn);
  } catch (const NumericalFailure&) {
    throw;
  } catch (const std::runtime_error& e) {
    // Spectra's own failures (its Schur or eigen decompositions of the Rayleigh quotient, e.g. on
    // a non-finite operator) are numerical, not a bug of the caller: exit 3 with its reason.
    throw NumericalFailure(std::string("Krylov (spectra): ") + e.what());
  }
  RitzPairs pairs;
  pairs.converged = static_cast<int>(nconv);
  // Spectra counts one more than it checked when it gives up: its loop restarts max_iterations
  // times and stops without testing the last restart (GenEigsBase::compute, num_iterations =
  // restarts + 1). The iterations that counted against max_iterations = 1 + max_restarts are the
  // tested ones, so the count never exceeds the limit the message names.
  pairs.iterations = static_cast<int>(std::min<Eigen::Index>(solver.num_iterations(), s.max_iterations));
  if (solver.info() != Spectra::CompInfo::Successful || nconv < s.nev)
    throw NumericalFailure(
        "Krylov (spectra) did not converge: " + std::to_string(nconv) + " of nev = " + std::to_string(s.nev) +
        " Ritz values converged after " + std::to_string(pairs.iterations) +
        " Arnoldi iterations (max_iterations = " + std::to_string(s.max_iterations) +
        " = 1 + max_restarts, ncv = " + std::to_string(s.ncv) + "), largest relative residual estimate " +
        format_number(solver.largest_estimate()) + " > tol " + format_number(s.tolerance, 3));

  std::vector<std::complex<double>> theta;
  std::vector<Eigen::VectorXcd> y;
  for (int i = 0; i < s.nev; ++i) {
    theta.push_back(solver.value(i) * scale);  // exact: scale is a power of two
    y.push_back(solver.coefficients(i));
  }
  const int converged = pairs.converged, iterations = pairs.iterations;
  pairs = ritz_pairs_in_basis(theta, y, solver.basis());
  pairs.converged = converged;
  pairs.iterations = iterations;
  return pairs;
}

}  // namespace delayspec::krylov
