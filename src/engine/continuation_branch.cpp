// The branch tracer and the bifurcation locator (detail/continuation_branch.hpp,
// detail/bifurcation_locator.hpp), compiled once over the abstract BranchProblem, and the
// corrector and parameter derivative every problem uses (branch_corrector.hpp): every model's
// continuation (the built-in ones, the objects compiled from a scene's equations) instantiates only
// its own problem along the branch.
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>

#include "delayspec/detail/continuation_branch.hpp"

namespace delayspec::continuation_detail {

std::optional<BranchState> bordered_corrector(const Linearise& linearise, Eigen::VectorXd x, double p,
                                              const Eigen::VectorXd& row_x, double row_p, double target,
                                              int max_iterations, double tolerance, double weight, std::string& why,
                                              double& seconds) {
  const ScopedSeconds timer(seconds);
  const long n = x.size();
  double first = INFINITY;
  for (int it = 0;; ++it) {
    Eigen::VectorXd G, Gp;
    Eigen::SparseMatrix<double> Gx;
    if (!linearise(x, p, G, Gx, Gp, why)) return std::nullopt;
    const double r = G.lpNorm<Eigen::Infinity>();
    const double g = row_x.dot(x) + row_p * p - target;
    if (!std::isfinite(r)) {
      why = "non-finite residual, |F|_inf = " + format_number(r) + " at parameter " + format_number(p);
      return std::nullopt;
    }
    // g is linear: after one Newton step it is at its rounding level, eps times the size of its terms
    const double g_scale = row_x.cwiseAbs().dot(x.cwiseAbs()) + std::abs(row_p * p) + std::abs(target);
    const bool converged = r <= tolerance * (1 + x.lpNorm<Eigen::Infinity>()) && std::abs(g) <= 1e-12 * (1 + g_scale);
    if (it == 1) first = r;
    if (!converged && (it >= max_iterations || r > 1e3 * first)) {
      why = (it >= max_iterations ? "not converged in " + std::to_string(it) + " iterations"
                                  : "residual diverging at iteration " + std::to_string(it)) +
            ", |F|_inf = " + format_number(r) + " at parameter " + format_number(p);
      return std::nullopt;
    }
    std::optional<SparseLU> lu;
    try {
      lu.emplace(bordered_matrix(Gx, Gp, row_x, row_p));  // sparse_lu.hpp
    } catch (const NumericalFailure& e) {
      why = std::string("bordered matrix singular at parameter ") + format_number(p) + " (" + e.what() + ")";
      return std::nullopt;
    }
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n + 1);
    if (converged) {  // the tangent z: [G_x G_p; row] z = e_{n+1}, z / |z|_w
      rhs[n] = 1;
      const Eigen::VectorXd z = lu->solve(rhs);
      const double norm = std::sqrt(weight * z.head(n).squaredNorm() + z[n] * z[n]);
      return BranchState{std::move(x), p, z.head(n) / norm, z[n] / norm, it, r};
    }
    rhs.head(n) = -G;
    rhs[n] = -g;
    const Eigen::VectorXd step = lu->solve(rhs);
    x += step.head(n);
    p += step[n];
  }
}

Eigen::VectorXd parameter_derivative(const std::function<Eigen::VectorXd(double)>& residual_at, double p,
                                     const Eigen::VectorXd& G, double scale) {
  const double delta = std::cbrt(std::numeric_limits<double>::epsilon()) * std::max({std::abs(p), scale, 1e-300});
  const double up = p + delta, down = p - delta;
  std::exception_ptr rejected;
  auto accepted = [&](double q) -> std::optional<Eigen::VectorXd> {
    try {
      return residual_at(q);
    } catch (const BadInput&) {
      rejected = std::current_exception();
      return std::nullopt;
    }
  };
  const std::optional<Eigen::VectorXd> G_up = accepted(up), G_down = accepted(down);
  if (G_up && G_down) return (*G_up - *G_down) / (up - down);
  if (!G_up && !G_down) std::rethrow_exception(rejected);
  const double side = G_up ? delta : -delta;
  const double s1 = (p + side) - p, s2 = (p + 2 * side) - p;  // the steps as represented
  const Eigen::VectorXd& G1 = G_up ? *G_up : *G_down;
  const Eigen::VectorXd G2 = residual_at(p + 2 * side);
  // Quadratic through (0, G), (s1, G1), (s2, G2), differentiated at 0.
  return (-(s1 + s2) / (s1 * s2)) * G + (s2 / (s1 * (s2 - s1))) * G1 - (s1 / (s2 * (s2 - s1))) * G2;
}


ContinuationResult trace_branch(const BranchProblem& branch, const Eigen::VectorXd& guess,
                                const ContinuationOptions& options, const Eigen::VectorXd* start_tangent,
                                double start_p) {
  const auto run_start = std::chrono::steady_clock::now();
  BranchTracer tracer(branch, options, start_tangent, start_p);
  ContinuationResult result = tracer.trace(guess);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - run_start).count();
  return result;
}

}  // namespace delayspec::continuation_detail
