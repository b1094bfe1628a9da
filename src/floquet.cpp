#include "delayspec/floquet.hpp"

#include <chrono>

#include "delayspec/dense_spectrum.hpp"
#include "delayspec/errors.hpp"

namespace delayspec {

FloquetSolver parse_floquet_solver(const std::string& name) {
  if (name == "spectra") return FloquetSolver::spectra;
  if (name == "arpack") return FloquetSolver::arpack;
  if (name == "dense" || name == "dense-lapack") return FloquetSolver::dense_lapack;
  if (name == "dense-eigen") return FloquetSolver::dense_eigen;
  throw BadInput("`solver = " + name + "`: must be one of spectra, arpack, dense, dense-eigen, dense-lapack");
}

std::string to_string(FloquetSolver solver) {
  switch (solver) {
    case FloquetSolver::spectra: return "spectra";
    case FloquetSolver::arpack: return "arpack";
    case FloquetSolver::dense_eigen: return "dense-eigen";
    case FloquetSolver::dense_lapack: return "dense-lapack";
  }
  return "?";
}

template <int D>
FloquetResult floquet_multipliers(const Monodromy<D>& op, const FloquetOptions& options) {
  const long n = op.rows();
  if (options.nev < 1 || options.nev > n)
    throw BadInput("`nev = " + std::to_string(options.nev) + "`: must be between 1 and the dimension n = " +
                   std::to_string(n));
  const auto start = std::chrono::steady_clock::now();
  FloquetResult result;
  const long applications_before = op.applications();
  switch (options.solver) {
    case FloquetSolver::spectra:
    case FloquetSolver::arpack:
      throw BadInput("`solver = " + to_string(options.solver) +
                     "`: the Krylov solvers are not available yet; use solver = dense");
    case FloquetSolver::dense_eigen:
    case FloquetSolver::dense_lapack: {
      const DenseBackend backend =
          options.solver == FloquetSolver::dense_eigen ? DenseBackend::eigen : DenseBackend::lapack;
      auto values = dense_eigenvalues(op.to_dense(), backend);
      values.resize(options.nev);
      result.multipliers = std::move(values);
      break;
    }
  }
  result.solver = to_string(options.solver);
  result.operator_applications = op.applications() - applications_before;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

template FloquetResult floquet_multipliers<1>(const Monodromy<1>&, const FloquetOptions&);
template FloquetResult floquet_multipliers<2>(const Monodromy<2>&, const FloquetOptions&);

}  // namespace delayspec
