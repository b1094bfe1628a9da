#include "delayspec/floquet.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <numeric>

#include "delayspec/dense_spectrum.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/memory_budget.hpp"
#include "engine/linalg/blas.hpp"
#include "engine/linalg/linear_algebra.hpp"
#include "engine/eigen/krylov.hpp"

namespace delayspec {

FloquetSolver parse_floquet_solver(const std::string& name) {
  if (name == "auto") return FloquetSolver::automatic;
  if (name == "spectra") return FloquetSolver::spectra;
  if (name == "arpack") return FloquetSolver::arpack;
  if (name == "block") return FloquetSolver::block;
  if (name == "dense" || name == "dense-lapack") return FloquetSolver::dense_lapack;
  if (name == "dense-eigen") return FloquetSolver::dense_eigen;
  throw BadInput("`solver = " + name +
                 "`: must be one of auto, spectra, arpack, block, dense, dense-eigen, dense-lapack");
}

FloquetSolver choose_floquet_solver(long n) {
  if (n <= 100) return FloquetSolver::dense_lapack;
  return n < 3000 ? FloquetSolver::spectra : FloquetSolver::block;
}

std::string to_string(FloquetSolver solver) {
  switch (solver) {
    case FloquetSolver::automatic: return "auto";
    case FloquetSolver::spectra: return "spectra";
    case FloquetSolver::arpack: return "arpack";
    case FloquetSolver::block: return "block";
    case FloquetSolver::dense_eigen: return "dense-eigen";
    case FloquetSolver::dense_lapack: return "dense-lapack";
  }
  return "?";
}

void validate_floquet_options(const FloquetOptions& options, long n) {
  if (options.nev < 1 || options.nev > n)
    throw BadInput("`nev = " + std::to_string(options.nev) +
                   "`: must be between 1 and the dimension n = " + std::to_string(n));
  // The Krylov options are checked whenever a Krylov backend may run (auto included, whatever
  // it picks): a bad ncv is an error of the request, not of the size that hides it.
  if (options.solver == FloquetSolver::dense_eigen || options.solver == FloquetSolver::dense_lapack) return;
  if (options.ncv != 0 && options.ncv < options.nev + 2)
    throw BadInput("`ncv = " + std::to_string(options.ncv) +
                   "`: must be 0 (automatic) or >= nev + 2 = " + std::to_string(options.nev + 2));
  if (!(options.tolerance > 0) || !std::isfinite(options.tolerance))
    throw BadInput("`tol = " + format_number(options.tolerance) + "`: must be > 0 and finite");
  if (options.max_iterations < 1)
    throw BadInput("`max_iterations = " + std::to_string(options.max_iterations) + "`: must be >= 1");
  if (!(options.residual_bound > 0) || !std::isfinite(options.residual_bound))
    throw BadInput("`residual_bound = " + format_number(options.residual_bound) + "`: must be > 0 and finite");
  if (options.block_size < 1 || options.block_size > 64)
    throw BadInput("`block_size = " + std::to_string(options.block_size) + "`: must be between 1 and 64");
}

int default_ncv(int nev, long n) {
  const long ncv = std::max(2L * nev + 1, static_cast<long>(nev) + 10);
  return static_cast<int>(std::min(ncv, n));
}

Eigen::VectorXd start_vector(long n, std::uint64_t seed) {
  Eigen::VectorXd v(n);
  std::uint64_t state = seed;
  for (long i = 0; i < n; ++i) {
    // SplitMix64 (Steele, Lea, Flood 2014)
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    v[i] = 2.0 * static_cast<double>(z >> 11) * 0x1.0p-53 - 1.0;  // uniform in [-1, 1)
  }
  return v;
}

namespace krylov {

RitzPairs ritz_pairs_in_basis(const std::vector<std::complex<double>>& theta, const std::vector<Eigen::VectorXcd>& y,
                              const Eigen::Ref<const Eigen::MatrixXd>& V) {
  RitzPairs pairs;
  std::vector<Eigen::VectorXcd> coefficients;
  for (size_t i = 0; i < theta.size(); ++i) {
    std::complex<double> mu = theta[i];
    Eigen::VectorXcd c = y[i];
    if (mu.imag() < 0) {
      if (std::find(theta.begin(), theta.end(), std::conj(mu)) != theta.end()) continue;  // partner listed
      mu = std::conj(mu);
      c = c.conjugate();
    }
    pairs.values.push_back(mu);
    coefficients.push_back(std::move(c));
  }
  long columns = 0;
  for (const auto& mu : pairs.values) {
    pairs.column.push_back(columns);
    columns += mu.imag() == 0 ? 1 : 2;
  }
  Eigen::MatrixXd C(V.cols(), columns);
  for (size_t i = 0; i < pairs.values.size(); ++i) {
    C.col(pairs.column[i]) = coefficients[i].real();
    if (pairs.values[i].imag() != 0) C.col(pairs.column[i] + 1) = coefficients[i].imag();
  }
  pairs.vectors.resize(V.rows(), columns);  // Ritz vectors x = V y, real form (BLAS: V is tall)
  gemm('N', 'N', V.rows(), columns, V.cols(), 1.0, V.data(), V.outerStride(), C.data(), C.rows(), 0.0,
       pairs.vectors.data(), V.rows());
  return pairs;
}

double largest_relative_estimate(const std::vector<std::complex<double>>& theta, const std::vector<double>& estimate,
                                 int nev) {
  const double eps23 = std::pow(std::numeric_limits<double>::epsilon(), 2.0 / 3.0);
  std::vector<size_t> order(theta.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return std::abs(theta[a]) > std::abs(theta[b]); });
  double worst = 0;
  for (size_t k = 0; k < order.size() && k < static_cast<size_t>(nev); ++k) {
    const size_t i = order[k];
    worst = std::max(worst, estimate[i] / std::max(std::abs(theta[i]), eps23));
  }
  return worst;
}

}  // namespace krylov

namespace {

// Absolute residuals |M v - mu v| / |v| of the Ritz pairs, from applying M to the Ritz vectors
// (real form) one at a time. Not apply_block: at large n its interleaved buffer holds the whole
// extended history of every vector of the block (256 MB for 8 vectors at N = 10^6), first touched
// here, while perform_op's buffer is already warm from the Krylov iterations (measured at
// N = 10^6, 31 columns: 0.36 s in blocks of 8 against ~0.1 s one at a time).
std::vector<double> ritz_residuals(const LinearOperator& op, const krylov::RitzPairs& pairs) {
  const long n = op.rows();
  std::vector<double> residual(pairs.values.size(), 0.0);
  Eigen::VectorXd Ma(n), Mb(n);
  for (size_t i = 0; i < pairs.values.size(); ++i) {
    const std::complex<double> mu = pairs.values[i];
    const auto a = pairs.vectors.col(pairs.column[i]);
    op.perform_op(a.data(), Ma.data());
    if (mu.imag() == 0) {
      // |M a - mu a| / |a|
      residual[i] = (Ma - mu.real() * a).norm() / a.norm();
      continue;
    }
    // v = a + i b, mu = al + i be:  M v - mu v = (M a - al a + be b) + i (M b - al b - be a)
    const auto b = pairs.vectors.col(pairs.column[i] + 1);
    op.perform_op(b.data(), Mb.data());
    const double al = mu.real(), be = mu.imag();
    const double re = (Ma - al * a + be * b).squaredNorm(), im = (Mb - al * b - be * a).squaredNorm();
    residual[i] = std::sqrt(re + im) / std::sqrt(a.squaredNorm() + b.squaredNorm());
  }
  return residual;
}

// The nev leading multipliers from the Ritz pairs: both conjugates of each complex pair, sorted
// like the dense reference, with their relative residuals |M v - mu v| / (|mu| |v|) (absolute
// ones in `absolute`), and vectors when asked.
void take_leading_pairs(const krylov::RitzPairs& pairs, const std::vector<double>& residual,
                        const FloquetOptions& options, const std::string& name, FloquetResult& result,
                        std::vector<double>& absolute) {
  struct Entry {
    std::complex<double> value;
    size_t pair;
    bool conjugate;
  };
  std::vector<Entry> entries;
  for (size_t i = 0; i < pairs.values.size(); ++i) {
    const auto mu = pairs.values[i];
    if (!std::isfinite(mu.real()) || !std::isfinite(mu.imag()))
      throw NumericalFailure(name + ": non-finite Ritz value");
    entries.push_back({mu, i, false});
    if (mu.imag() != 0) entries.push_back({std::conj(mu), i, true});
  }
  if (static_cast<int>(entries.size()) < options.nev)
    throw NumericalFailure(name + ": only " + std::to_string(entries.size()) +
                           " Ritz values returned for nev = " + std::to_string(options.nev));
  std::vector<std::complex<double>> sorted;
  for (const auto& e : entries) sorted.push_back(e.value);
  sort_by_modulus(sorted);
  sorted.resize(options.nev);
  const long n = pairs.vectors.rows();
  if (options.keep_vectors) result.subspace.resize(n, options.nev);
  for (int k = 0; k < options.nev; ++k) {
    const auto it = std::find_if(entries.begin(), entries.end(), [&](const Entry& e) { return e.value == sorted[k]; });
    result.multipliers.push_back(it->value);
    absolute.push_back(residual[it->pair]);
    result.residuals.push_back(residual[it->pair] / std::abs(it->value));
    if (options.keep_vectors)
      result.subspace.col(k) = pairs.vectors.col(pairs.column[it->pair] + (it->conjugate ? 1 : 0));
  }
}

// Indices of the relative residuals above `bound` (NaN counts as above), in order.
std::vector<size_t> failing_pairs(const std::vector<double>& residuals, double bound) {
  std::vector<size_t> failing;
  for (size_t k = 0; k < residuals.size(); ++k)
    if (!(residuals[k] <= bound)) failing.push_back(k);
  return failing;
}

// Multipliers at the round-off level of the operator. A monodromy may have exact zeros (k = 0
// makes the impact model an ODE: rank d; b = 0 a linear one: rank 1) or multipliers far below
// eps |M|: no eigensolver gets their digits (rounding of one application alone makes the relative
// residual O(1)), but a pair with |mu| <= r and |M v - mu v| / |v| <= r, r = 1e3 eps |M x| / |x|,
// is an eigenpair of M + E with |E| ~ r, i.e. zero to working precision. Those are returned as
// exactly 0 (the honest value: 0 +- r), residual |M v| / (|M x| / |x| |v|), and named in `note`;
// they leave `failing`. A pair with |mu| > r whose absolute residual is at that level is as good
// as the operator allows (x' = -x + 1e-8 x(t - 1): mu_2 = 6e-10 next to mu_1 = 0.37, |M v - mu v|
// / |v| = 1.5e-15, relative to |mu| 2e-6): kept, with its relative residual, and named in `note`;
// it leaves `failing` too (it failed the relative gate before: exit 3; issue 32, item 2). Its
// digits are the residual times its condition number, unknown here and large for such clusters
// (dense and Krylov differ by 25 % on that mu_2): the error bars (error_bars.hpp) say how far it
// is. Returns how many were zeroed.
size_t zero_round_off_pairs(FloquetResult& r, const std::vector<double>& absolute, std::vector<size_t>& failing,
                            double size) {
  const double level = 1e3 * std::numeric_limits<double>::epsilon() * size;
  std::vector<size_t> still_failing, zeroed, at_level;
  for (size_t k : failing) {
    if (std::abs(r.multipliers[k]) <= level && absolute[k] <= level) {
      r.multipliers[k] = 0;
      r.residuals[k] = absolute[k] / size;
      zeroed.push_back(k);
    } else if (absolute[k] <= level) {
      at_level.push_back(k);
    } else {
      still_failing.push_back(k);
    }
  }
  failing.swap(still_failing);
  if (!at_level.empty()) {
    double worst = 0;
    for (size_t k : at_level) worst = std::max(worst, absolute[k]);
    r.note += std::string(r.note.empty() ? "" : "; ") + "multipliers " + std::to_string(at_level.front() + 1) + ".." +
              std::to_string(at_level.back() + 1) + " have residuals at the operator's round-off level (|M v - mu v| / " +
              "|v| <= " + format_number(worst) + "): known to that level times their condition number, which " +
              "for multipliers this small next to mu_1 can be large; their relative digits are not vouched for";
  }
  if (!zeroed.empty())
    r.note += std::string(r.note.empty() ? "" : "; ") + "multipliers " + std::to_string(zeroed.front() + 1) + ".." +
              std::to_string(zeroed.back() + 1) +
              " are at the operator's round-off level (|mu| <= " + format_number(level) + "): reported as 0";
  return zeroed.size();
}

// |M x| / |x|: a lower bound of the operator's norm (within sqrt(n) of it for a random x).
double operator_size(const LinearOperator& op, const Eigen::VectorXd& x) {
  Eigen::VectorXd y(op.rows());
  op.perform_op(x.data(), y.data());
  return y.norm() / x.norm();
}

// Why the gate failed, with the numbers of the first failing multiplier; when its modulus is at
// the round-off level of the operator (|mu| <= 1e3 eps |M x| / |x|, x the start vector: rounding
// of one application alone makes its relative residual O(1)), say so: no method resolves it next
// to larger ones, and the multipliers before it are what can be asked for.
// `size` = operator_size(op, start).
std::string residual_gate_message(double size, const FloquetResult& r, const std::vector<size_t>& failing, double bound,
                                  const std::string& name, int first_ncv, int last_ncv) {
  const size_t k = failing.front();
  const std::complex<double> mu = r.multipliers[k];
  const std::string others =
      failing.size() > 1 ? " (and " + std::to_string(failing.size() - 1) + " more after it)" : "";
  std::string message = name + ": multiplier " + std::to_string(k + 1) + others +
                        " of nev = " + std::to_string(r.multipliers.size()) + ", mu = " + format_number(mu.real()) +
                        (mu.imag() < 0 ? " - " : " + ") + format_number(std::abs(mu.imag())) +
                        "i, fails its residual check: |M v - mu v| / (|mu| |v|) = " + format_number(r.residuals[k]) +
                        " > bound " + format_number(bound, 3) + " (ncv = " + std::to_string(first_ncv) +
                        (last_ncv != first_ncv ? ", retried with ncv = " + std::to_string(last_ncv) : "") + ")";
  const double round_off = std::numeric_limits<double>::epsilon() * size;
  if (std::abs(mu) <= 1e3 * round_off)
    message += "; |mu| is at the round-off level of this operator (eps |M x| / |x| = " + format_number(round_off) +
               " next to |mu_1| = " + format_number(std::abs(r.multipliers[0])) + "): no eigensolver resolves it" +
               (k > 0 ? ", ask for fewer multipliers (nev = " + std::to_string(k) + ")" : "");
  else message += "; try a larger ncv or another solver";
  return message;
}

void krylov_solve(const LinearOperator& op, const FloquetOptions& options, FloquetResult& result) {
  const long n = op.rows();
  krylov::Settings settings;
  settings.nev = options.nev;
  settings.ncv = options.ncv == 0 ? default_ncv(options.nev, n) : options.ncv;
  settings.tolerance = options.tolerance;
  settings.max_iterations = options.max_iterations;
  settings.block_size = options.block_size;
  if (settings.ncv < options.nev + 2)
    throw BadInput("`ncv = " + std::to_string(settings.ncv) +
                   "`: must be >= nev + 2 = " + std::to_string(options.nev + 2));
  if (settings.ncv > n) {
    result.note = "ncv = " + std::to_string(settings.ncv) + " reduced to the dimension n = " + std::to_string(n);
    settings.ncv = static_cast<int>(n);
  }
  require_memory(8.0 * static_cast<double>(n) * settings.ncv,
                 "`ncv = " + std::to_string(settings.ncv) + "` with n = " + std::to_string(n),
                 "the Krylov basis: ncv vectors of the history's n = d (N + 1) doubles");
  Eigen::VectorXd start;
  if (options.start.size() == 0) {
    start = start_vector(n, options.seed);
  } else {
    if (options.start.size() != n)
      throw BadInput("FloquetOptions::start has " + std::to_string(options.start.size()) +
                     " entries, the operator is " + std::to_string(n) + " x " + std::to_string(n));
    if (!options.start.allFinite() || options.start.norm() == 0)
      throw BadInput("FloquetOptions::start: must be finite and not zero");
    start = options.start;
  }
  const double bound = std::max(options.residual_bound, 100 * options.tolerance);
  const std::string name = "Krylov (" + to_string(options.solver) + ")";

  // One solve, then the residual gate; on failure one retry with ncv doubled (at most n).
  const int first_ncv = settings.ncv;
  double size = -1;  // operator_size(op, start), computed on the first failing pair
  // The retry: ncv doubled (at most n); Spectra's breakdown thresholds are absolute
  // (krylov_spectra.cpp), so it also runs on M / s with |M / s| <= 1 / sqrt(n) or so, |M x| / |x|
  // underestimating |M| by up to sqrt(n).
  std::string retry_reason;   // why the first attempt was not taken
  std::string first_failure;  // the first attempt's own message when it did not converge
  // A failure of the retry says that it was one, and what the first attempt gave: each message
  // counts its own attempt's iterations against max_iterations and names its own ncv.
  auto retry_failed = [&](const std::string& message) {
    return NumericalFailure(message + " [this was the retry with ncv = " + std::to_string(settings.ncv) +
                            (settings.scale != 1 ? " on M / " + format_number(settings.scale) : "") +
                            "; the first attempt, with ncv = " + std::to_string(first_ncv) +
                            (first_failure.empty() ? "," + retry_reason : ": " + first_failure) + "]");
  };
  auto prepare_retry = [&] {
    settings.ncv = static_cast<int>(std::min<long>(n, 2L * settings.ncv));
    if (options.solver == FloquetSolver::spectra) {
      if (size < 0) size = operator_size(op, start);
      if (size > 0 && std::isfinite(size))
        settings.scale = std::ldexp(1.0, static_cast<int>(std::lround(std::log2(size * std::sqrt(double(n))))));
    }
  };
  for (int attempt = 0;; ++attempt) {
    krylov::RitzPairs pairs;
    try {
      pairs = options.solver == FloquetSolver::block     ? krylov::block_ritz_pairs(op, settings, start)
              : options.solver == FloquetSolver::spectra ? krylov::spectra_ritz_pairs(op, settings, start)
                                                         : krylov::arpack_ritz_pairs(op, settings, start);
    } catch (const NumericalFailure& e) {
      // The same absolute thresholds can also keep Spectra from converging at all on an operator
      // of norm >> 1 (measured: x' = 5 x, N = 50, rank one, 0 of 1 converged in 300 restarts after
      // a change of the step's rounding): the same retry as for a pair failing the gate.
      if (attempt > 0) throw retry_failed(e.what());
      if (!options.retry_failed_gate || options.solver != FloquetSolver::spectra) throw;
      retry_reason = " did not converge";
      first_failure = e.what();
      prepare_retry();
      continue;
    }
    const std::vector<double> residual = ritz_residuals(op, pairs);
    FloquetResult candidate = result;
    std::vector<double> absolute;
    take_leading_pairs(pairs, residual, options, name, candidate, absolute);
    std::vector<size_t> failing = failing_pairs(candidate.residuals, bound);
    // |M x| / |x| costs one application: only when a pair fails, and once per solve.
    if (!failing.empty()) {
      if (size < 0) size = operator_size(op, start);
      zero_round_off_pairs(candidate, absolute, failing, size);
    }
    candidate.ncv = settings.ncv;
    candidate.converged = pairs.converged;
    candidate.iterations = pairs.iterations;
    candidate.restarts = std::max(0, pairs.iterations - 1);
    if (failing.empty()) {
      if (attempt > 0)
        candidate.note += std::string(candidate.note.empty() ? "" : "; ") + "ncv = " + std::to_string(first_ncv) +
                          retry_reason + ", retried with ncv = " + std::to_string(settings.ncv) +
                          (settings.scale != 1 ? " on M / " + format_number(settings.scale) : "");
      result = std::move(candidate);
      return;
    }
    if (attempt == 0 && options.retry_failed_gate) {
      retry_reason = " gave a pair failing the residual gate";
      prepare_retry();
      continue;
    }
    throw NumericalFailure(residual_gate_message(size, candidate, failing, bound, name, first_ncv, settings.ncv));
  }
}

// solver = auto: the backend chosen by size first; where it fails (its residual gate after its
// own retry, or no convergence), the other Krylov backends in turn, then the dense solver where n
// is small enough for it (kDenseFallback: about a second); the backend that answered is returned,
// and `note` says what failed before it. Only when every one fails, a NumericalFailure naming each
// (issue 61: the block Krylov-Schur failed the gate on a 6th multiplier where ARPACK, Spectra and
// dense all answered).
constexpr long kDenseFallback = 1500;

FloquetSolver automatic_krylov_solve(const LinearOperator& op, const FloquetOptions& options, FloquetResult& result) {
  std::vector<FloquetSolver> order{options.solver};
  for (FloquetSolver s : {FloquetSolver::block, FloquetSolver::spectra, FloquetSolver::arpack})
    if (s != options.solver) order.push_back(s);
  if (op.rows() <= kDenseFallback) order.push_back(FloquetSolver::dense_lapack);
  std::string failures;
  for (FloquetSolver s : order) {
    FloquetResult attempt = result;
    try {
      if (s == FloquetSolver::dense_lapack) {
        auto values = dense_eigenvalues(op.to_dense(), DenseBackend::lapack);
        values.resize(static_cast<size_t>(options.nev));
        attempt.multipliers = std::move(values);
        attempt.converged = options.nev;
      } else {
        FloquetOptions o = options;
        o.solver = s;
        if (s == FloquetSolver::arpack) detail::arpack();
        krylov_solve(op, o, attempt);
      }
    } catch (const NumericalFailure& e) {
      failures += (failures.empty() ? "" : "; ") + to_string(s) + ": " + e.what();
      continue;
    } catch (const BadInput& e) {  // dense on an operator that is not finite: a numerical failure here
      if (s != FloquetSolver::dense_lapack) throw;  // the options themselves (a start vector of the wrong size)
      failures += (failures.empty() ? "" : "; ") + to_string(s) + ": " + e.what();
      continue;
    }
    if (!failures.empty())
      attempt.note += std::string(attempt.note.empty() ? "" : "; ") + "solver = auto: answered by " + to_string(s) +
                      " after " + failures;
    result = std::move(attempt);
    return s;
  }
  throw NumericalFailure("solver = auto: every eigensolver failed (" + failures + ")");
}

}  // namespace

FloquetResult floquet_multipliers(const LinearOperator& op, const FloquetOptions& requested) {
  const long n = op.rows();
  validate_floquet_options(requested, n);
  FloquetOptions options = requested;
  if (options.solver == FloquetSolver::automatic) options.solver = choose_floquet_solver(n);
  const bool krylov = options.solver == FloquetSolver::spectra || options.solver == FloquetSolver::arpack ||
                      options.solver == FloquetSolver::block;
  FloquetResult result;
  FloquetSolver solver = options.solver;
  if (krylov && options.nev > n - 2) {
    result.note = "nev = " + std::to_string(options.nev) + " > n - 2 = " + std::to_string(n - 2) + ": Krylov (" +
                  to_string(options.solver) + ") needs nev <= n - 2, used the dense LAPACK solver";
    solver = FloquetSolver::dense_lapack;
  }
  // The solver's library is loaded (on first use, ~2 ms: linear_algebra.hpp) before the clock
  // starts, so that `seconds` is the solve's, the same in a process's first call as in later ones.
  if (solver != FloquetSolver::dense_eigen) detail::lapack();  // dgemm of the Ritz vectors, dgees, dgeev
  if (solver == FloquetSolver::arpack) detail::arpack();
  const auto start = std::chrono::steady_clock::now();
  const long applications_before = op.applications();
  switch (solver) {
    case FloquetSolver::automatic:  // resolved above
    case FloquetSolver::spectra:
    case FloquetSolver::arpack:
    case FloquetSolver::block:
      if (requested.solver == FloquetSolver::automatic) {
        solver = automatic_krylov_solve(op, options, result);
        break;
      }
      krylov_solve(op, options, result);
      break;
    case FloquetSolver::dense_eigen:
    case FloquetSolver::dense_lapack: {
      const DenseBackend backend = solver == FloquetSolver::dense_eigen ? DenseBackend::eigen : DenseBackend::lapack;
      auto values = dense_eigenvalues(op.to_dense(), backend);
      values.resize(options.nev);
      result.multipliers = std::move(values);
      result.converged = options.nev;
      break;
    }
  }
  result.solver = solver;
  result.operator_applications = op.applications() - applications_before;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace delayspec
