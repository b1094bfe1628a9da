#pragma once
// Floquet multipliers: the largest-modulus eigenvalues of a Monodromy (design.md 1.6).
// One entry point, several backends on the same matrix-free operator:
//   spectra: Spectra 1.0 GenEigsSolver (implicitly restarted Arnoldi) with the Monodromy as op;
//   arpack:  ARPACK-ng dnaupd/dneupd reverse communication calling the same perform_op;
//   block:   Krylov-Schur (krylov_block.cpp; restarts by LAPACK dgees with the wanted values
//            first). block_size = 1 (default): one vector per product, Gram-Schmidt with delayed
//            reorthogonalisation (DCGS2), two threaded passes over the basis per product: auto's
//            choice at large n. block_size = b > 1: apply_block on b vectors, BLAS-3 CGS2 +
//            Cholesky QR2 with deflation; measured slower (more products for the same accuracy);
//   dense_eigen / dense_lapack: form the n x n matrix, all eigenvalues (reference, O(n^3)).
//
// Both Krylov backends start from the same vector (start_vector(n, seed), reproducible),
// stop when every wanted Ritz pair has the Arnoldi residual estimate
//     |M x - theta x| <= tolerance * max(|theta|, eps^(2/3))      (x unit Ritz vector)
// (the criterion Spectra and ARPACK share), and are then checked a posteriori: the Ritz vectors
// are formed and applied once more (one extra apply_block), giving the true residual
// |M v - mu v| / (|mu| |v|) of each returned pair in FloquetResult::residuals.
//
// The residual gate: a returned pair counts as converged only if its true residual is at most
//     bound = max(residual_bound, 100 tolerance)                 (default 1e-8)
// The backends' estimate is <= tolerance and the true residual equals it up to the rounding of
// one application and the basis' loss of orthogonality, O(eps K) ~ 1e-16 ... 1e-9 for K <= 1e7
// steps; a pair far above its own estimate (spurious Ritz values from a basis grown out of
// round-off, a multiplier below the operator's round-off level eps |M|) is not what Arnoldi
// converged to. A failing pair is retried once with ncv doubled (at most n; Spectra also on a
// scaled operator, krylov_spectra.cpp); if it still fails, NumericalFailure names the multiplier,
// its residual and the bound. Never returned with exit 0. Under solver = auto the other Krylov
// backends are tried in turn, then dense for n <= 1500, before that failure; FloquetResult::solver
// is the one that answered and `note` says what failed first.
// Exception: multipliers at the operator's round-off level, |mu| <= r and |M v - mu v| <= r |v|
// with r = 1e3 eps |M x| / |x| (exact zeros of a rank-deficient monodromy, e.g. k = 0 or b = 0,
// or values far below eps |M|), are zero to working precision: returned as exactly 0, residual
// |M v| / (|v| |M x| / |x|), and named in `note`.
//
// Example:
//   FloquetOptions o;  o.nev = 20;  o.solver = FloquetSolver::arpack;
//   FloquetResult r = floquet_multipliers(monodromy, o);   // r.multipliers[0] = spectral radius
//
// Errors: BadInput (nev < 1 or > n, ncv < nev + 2, tolerance <= 0, max_iterations < 1,
// residual_bound <= 0);
// NumericalFailure when a Krylov backend does not converge within max_iterations (the message
// names the iterations, the converged count and the largest relative Ritz residual estimate) or
// reports an error (ARPACK info != 0), or when a returned pair fails the residual gate.
// Never a silently shorter list.
// Krylov needs nev <= n - 2 (Spectra's and ARPACK's constraint); a larger nev with
// solver = spectra | arpack runs the dense LAPACK path instead and says so in `note`.
#include <complex>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "delayspec/monodromy.hpp"
#include "delayspec/multipliers.hpp"

namespace delayspec {

enum class FloquetSolver { automatic, spectra, arpack, block, dense_eigen, dense_lapack };

// "auto", "spectra", "arpack", "block", "dense" (= dense_lapack), "dense-eigen", "dense-lapack"; BadInput
// otherwise.
FloquetSolver parse_floquet_solver(const std::string& name);
std::string to_string(FloquetSolver solver);

// solver = auto: the backend measured fastest for the operator's size (docs/benchmarks.md,
// "Choosing the eigensolver"): dense LAPACK for n <= 100 (all eigenvalues, no Krylov constraint,
// as fast as Krylov there), Spectra for n < 3000, and from n = 3000 the one-vector Krylov-Schur
// (block, block_size = 1), whose Gram-Schmidt reads the basis twice per product (ARPACK's four
// times), in AVX2 passes on all cores: nev = 10 and 20, it is 1.03-1.7x faster than ARPACK from
// n = 2000 to 200000 and 2x at n = 2e6, and overtakes Spectra between n = 2500 and 3500. ARPACK,
// the fastest from n = 2000 before the passes had AVX2 kernels, stays available by name.
FloquetSolver choose_floquet_solver(long n);

struct FloquetOptions {
  int nev = 6;                                      // multipliers wanted
  FloquetSolver solver = FloquetSolver::automatic;  // choose_floquet_solver(n)
  // Krylov only:
  int ncv = 0;                    // Krylov subspace dimension; 0 = default_ncv(nev, n); clamped to n
  double tolerance = 1e-12;       // relative Ritz residual at which a pair counts as converged
  int max_iterations = 300;       // Arnoldi iterations (1 + implicit restarts), ARPACK's MXITER
  std::uint64_t seed = 1;         // start vector = start_vector(n, seed) for both backends
  int block_size = 1;             // solver = block: vectors per block (1..64); 1 = one-vector Krylov-Schur
  Eigen::VectorXd start;          // when non-empty: the start vector instead (n finite entries, not all 0)
  bool keep_vectors = false;      // fill FloquetResult::subspace (Krylov only)
  double residual_bound = 1e-8;   // the residual gate (header comment): max(residual_bound, 100 tolerance)
  bool retry_failed_gate = true;  // retry a pair failing the gate (false: report the backend's first answer)
};

struct FloquetResult {
  std::vector<std::complex<double>> multipliers;  // sorted by modulus, largest first (sort_by_modulus)
  // The backend that produced them (never automatic).
  FloquetSolver solver = FloquetSolver::automatic;
  long operator_applications = 0;  // single-vector applications of the operator (all of them)
  double seconds = 0;              // wall time of the eigen-solve (incl. assembly / residuals)
  std::string note;                // e.g. why a Krylov request went dense
  // Krylov only (dense: converged = nev, the rest 0 / empty):
  int ncv = 0;                    // subspace dimension used
  int converged = 0;              // Ritz values the backend reports converged (ARPACK iparam(5)), >= nev
  int iterations = 0;             // Arnoldi iterations taken (1 + restarts)
  int restarts = 0;               // implicit restarts = iterations - 1
  std::vector<double> residuals;  // per multiplier: |M v - mu v| / (|mu| |v|), from one extra application
                                  // (a multiplier reported as 0: |M v| / (|v| |M x| / |x|), header comment)
  // keep_vectors: n x nev real basis of the invariant subspace of the returned multipliers:
  // column k = Re v_k when Im mu_k >= 0, Im v_k otherwise (a conjugate pair spans {Re v, Im v}).
  Eigen::MatrixXd subspace;
};

// The options' rules for an n x n monodromy, each in one place, named by the CLI keys:
// 1 <= nev <= n; for Krylov and auto also ncv = 0 or ncv >= nev + 2, tolerance > 0 and finite,
// max_iterations >= 1, residual_bound > 0 and finite. BadInput "`key = v`: must be ..." otherwise.
// floquet_multipliers() calls it first; a command calls it before its heavy work (the orbit) to
// fail fast. (Krylov's nev <= n - 2 is not a rule: a larger nev runs the dense path.)
void validate_floquet_options(const FloquetOptions& options, long n);

// The nev leading multipliers of op (a Monodromy<D> of any d, or any LinearOperator). See the
// header comment for errors.
FloquetResult floquet_multipliers(const LinearOperator& op, const FloquetOptions& options);

// Default Krylov subspace dimension for nev wanted values of an n x n operator:
// min(n, max(2 nev + 1, nev + 10)).
int default_ncv(int nev, long n);

// The reproducible start vector of both Krylov backends: entries uniform in [-1, 1) from a
// SplitMix64 stream seeded with `seed` (platform independent).
Eigen::VectorXd start_vector(long n, std::uint64_t seed);

}  // namespace delayspec
