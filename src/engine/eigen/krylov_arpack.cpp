// ARPACK-ng backend of floquet_multipliers(): dnaupd / dneupd by reverse communication, the
// operator applied through the same Monodromy::perform_op Spectra uses.
//
// Every `info` is checked; the converged count is ARPACK's iparam(5), never assumed.
// ARPACK keeps state in Fortran SAVE variables, so calls are serialised by a mutex.
#include <arpack/arpackdef.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <mutex>
#include <string>

#include "delayspec/errors.hpp"
#include "engine/eigen/krylov.hpp"
#include "engine/linalg/linear_algebra.hpp"

namespace delayspec::krylov {

namespace {

std::mutex arpack_mutex;

std::string dnaupd_error(a_int info) {
  switch (info) {
    case 1: return "maximum number of iterations reached";
    case 3:
      return "no shifts could be applied during a cycle of the implicitly restarted Arnoldi iteration "
             "(increase ncv)";
    case -1: return "n must be positive";
    case -2: return "nev must be positive";
    case -3: return "ncv must satisfy nev + 2 <= ncv <= n";
    case -4: return "max_iterations must be positive";
    case -5: return "invalid `which`";
    case -6: return "invalid `bmat`";
    case -7: return "workl too short";
    case -8: return "error from the LAPACK eigenvalue calculation of the Hessenberg matrix";
    case -9: return "the starting vector is zero";
    case -10: return "invalid mode (iparam(7))";
    case -11: return "mode 1 requires bmat = I";
    case -12: return "invalid shift strategy (iparam(1))";
    case -9999: return "could not build an Arnoldi factorization (size of the current factorization in iparam(5))";
    default: return "unknown error";
  }
}

std::string dneupd_error(a_int info) {
  switch (info) {
    case 1: return "the Schur form from LAPACK dlahqr could not be reordered (dtrsen)";
    case -7: return "workl too short";
    case -8: return "error from LAPACK dlahqr computing the Schur form of the Hessenberg matrix";
    case -9: return "error from LAPACK dtrevc computing the eigenvectors";
    case -14: return "dnaupd did not find any eigenvalues to sufficient accuracy";
    case -15: return "dneupd got a different count of converged Ritz values than dnaupd";
    default: return "invalid argument (" + std::to_string(info) + ")";
  }
}

}  // namespace

RitzPairs arpack_ritz_pairs(const LinearOperator& op, const Settings& s, const Eigen::VectorXd& start) {
  if (op.rows() > INT_MAX)
    throw BadInput("solver = arpack: dimension n = " + std::to_string(op.rows()) +
                   " exceeds ARPACK's 32-bit integers; use solver = spectra");
  const a_int n = static_cast<a_int>(op.rows()), nev = s.nev, ncv = s.ncv;
  const a_int lworkl = 3 * ncv * ncv + 6 * ncv;
  const detail::Arpack& arpack = detail::arpack();
  std::lock_guard<std::mutex> lock(arpack_mutex);

  Eigen::VectorXd resid = start;  // info = 1 on entry: resid is the start vector
  Eigen::MatrixXd V(n, ncv);      // Arnoldi basis; dneupd overwrites its first nev + 1 columns with Ritz vectors
  std::vector<double> workd(3 * static_cast<size_t>(n)), workl(lworkl, 0.0);
  a_int iparam[11] = {}, ipntr[14] = {};
  iparam[0] = 1;                 // exact shifts
  iparam[2] = s.max_iterations;  // MXITER
  iparam[3] = 1;                 // block size (ARPACK supports only 1)
  iparam[6] = 1;                 // mode 1: standard problem M x = mu x
  a_int ido = 0, info = 1;

  for (;;) {
    arpack.dnaupd_c(&ido, "I", n, "LM", nev, s.tolerance, resid.data(), ncv, V.data(), n, iparam, ipntr, workd.data(),
                    workl.data(), lworkl, &info);
    if (ido == -1 || ido == 1) {
      // workd[ipntr(2)] = M workd[ipntr(1)]
      op.perform_op(&workd[ipntr[0] - 1], &workd[ipntr[1] - 1]);
      continue;
    }
    if (ido == 99) break;
    throw NumericalFailure("Krylov (arpack): dnaupd requested ido = " + std::to_string(ido) +
                           ", which mode 1 never does (info = " + std::to_string(info) + ")");
  }
  RitzPairs pairs;
  pairs.iterations = iparam[2];
  pairs.converged = iparam[4];
  if (info == 1 || (info == 0 && pairs.converged < nev)) {
    // workl holds the last ncv Ritz values (ipntr(6), ipntr(7)) and their estimates (ipntr(8)).
    std::vector<std::complex<double>> theta;
    std::vector<double> est;
    for (a_int i = 0; i < ncv; ++i) {
      theta.emplace_back(workl[ipntr[5] - 1 + i], workl[ipntr[6] - 1 + i]);
      est.push_back(std::abs(workl[ipntr[7] - 1 + i]));
    }
    throw NumericalFailure(
        "Krylov (arpack) did not converge: " + std::to_string(pairs.converged) + " of nev = " + std::to_string(nev) +
        " Ritz values converged after " + std::to_string(pairs.iterations) + " Arnoldi iterations (max_iterations = " +
        std::to_string(s.max_iterations) + " = 1 + max_restarts, ncv = " + std::to_string(ncv) +
        "), largest relative residual estimate " + format_number(largest_relative_estimate(theta, est, nev)) +
        " > tol " + format_number(s.tolerance, 3) + " (dnaupd info = " + std::to_string(info) + ")");
  }
  if (info != 0)
    throw NumericalFailure("Krylov (arpack): dnaupd info = " + std::to_string(info) + ": " + dnaupd_error(info) +
                           " (after " + std::to_string(pairs.iterations) + " iterations, ncv = " + std::to_string(ncv) +
                           ")");

  // Ritz vectors into the first columns of V (allowed by dneupd: Z may be V). dr/di get ncv
  // entries, not the documented nev + 1: iparam(5) can exceed nev + 1 (arpack-ng issue #465).
  std::vector<a_int> select(ncv, 1);
  std::vector<double> dr(ncv, 0.0), di(ncv, 0.0), workev(3 * static_cast<size_t>(ncv));
  a_int einfo = 0;
  arpack.dneupd_c(1, "A", select.data(), dr.data(), di.data(), V.data(), n, 0.0, 0.0, workev.data(), "I", n, "LM", nev,
                  s.tolerance, resid.data(), ncv, V.data(), n, iparam, ipntr, workd.data(), workl.data(), lworkl,
                  &einfo);
  if (einfo != 0)
    throw NumericalFailure("Krylov (arpack): dneupd info = " + std::to_string(einfo) + ": " + dneupd_error(einfo));
  const a_int nconv = std::min<a_int>(iparam[4], ncv);  // dneupd's count of converged Ritz values
  if (nconv < nev)
    throw NumericalFailure("Krylov (arpack): dneupd returned " + std::to_string(nconv) +
                           " Ritz values, nev = " + std::to_string(nev));
  for (a_int j = 0; j < nconv; ++j) {
    if (di[j] == 0) {
      pairs.values.emplace_back(dr[j], 0.0);
      pairs.column.push_back(j);
    } else if (di[j] > 0 && j + 1 < nconv && dr[j + 1] == dr[j] && di[j + 1] == -di[j]) {
      // Z(:, j) + i Z(:, j + 1) belongs to dr + i di; the next value is its conjugate.
      pairs.values.emplace_back(dr[j], di[j]);
      pairs.column.push_back(j);
      ++j;
    } else if (j + 1 == nconv && j >= nev) {
      // a trailing half pair beyond the nev wanted values: its imaginary part was not returned; drop it
    } else {
      throw NumericalFailure("Krylov (arpack): dneupd returned an unpaired complex Ritz value " + format_number(dr[j]) +
                             (di[j] < 0 ? " - " : " + ") + format_number(std::abs(di[j])) + "i at position " +
                             std::to_string(j) + " of " + std::to_string(nconv));
    }
  }
  pairs.vectors = std::move(V);
  return pairs;
}

}  // namespace delayspec::krylov
