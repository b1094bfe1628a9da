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
#include "delayspec/orbit_shooting.hpp"

namespace delayspec::continuation_detail {

namespace {

// The bordered matrix factored whole by UMFPACK on its first solve.
class LuLinearisation final : public BorderedLinearisation {
 public:
  LuLinearisation(Eigen::VectorXd residual, Eigen::SparseMatrix<double> G_x, Eigen::VectorXd G_p,
                  const Eigen::VectorXd& row_x, double row_p, double p)
      : G_x_(std::move(G_x)), G_p_(std::move(G_p)), row_x_(row_x), row_p_(row_p), p_(p) {
    G = std::move(residual);
  }

  std::optional<Eigen::VectorXd> solve(const Eigen::VectorXd& rhs_x, double rhs_p, double /*forcing*/,
                                       std::string& why) override {
    if (!lu_) {
      try {
        ++factorisations;
        lu_.emplace(bordered_matrix(G_x_, G_p_, row_x_, row_p_));  // sparse_lu.hpp
      } catch (const NumericalFailure& e) {
        why = std::string("bordered matrix singular at parameter ") + format_number(p_) + " (" + e.what() + ")";
        return std::nullopt;
      }
    }
    Eigen::VectorXd rhs(rhs_x.size() + 1);
    rhs << rhs_x, rhs_p;
    return lu_->solve(rhs);
  }

 private:
  Eigen::SparseMatrix<double> G_x_;
  Eigen::VectorXd G_p_;
  const Eigen::VectorXd& row_x_;
  double row_p_, p_;
  std::optional<SparseLU> lu_;
};

}  // namespace

std::unique_ptr<BorderedLinearisation> lu_linearisation(Eigen::VectorXd G, Eigen::SparseMatrix<double> G_x,
                                                        Eigen::VectorXd G_p, const Eigen::VectorXd& row_x,
                                                        double row_p, double p) {
  return std::make_unique<LuLinearisation>(std::move(G), std::move(G_x), std::move(G_p), row_x, row_p, p);
}

std::optional<BranchState> bordered_corrector(const Linearise& linearise, Eigen::VectorXd x, double p,
                                              const Eigen::VectorXd& row_x, double row_p, double target,
                                              int max_iterations, double tolerance, double weight,
                                              const CorrectorForcing& forcing, std::string& why, double& seconds,
                                              CorrectorWork& work) {
  const ScopedSeconds timer(seconds);
  const long n = x.size();
  double first = INFINITY;
  double eta = forcing.forcing_max, previous_norm = NAN;
  std::unique_ptr<BorderedLinearisation> lin;
  auto account = [&] {
    if (lin) work.factorisations += lin->factorisations, work.products += lin->products;
  };
  for (int it = 0;; ++it) {
    account();
    lin = linearise(x, p, why);
    if (!lin) return std::nullopt;
    const Eigen::VectorXd& G = lin->G;
    const double r = G.lpNorm<Eigen::Infinity>();
    const double g = row_x.dot(x) + row_p * p - target;
    if (!std::isfinite(r)) {
      why = "non-finite residual, |F|_inf = " + format_number(r) + " at parameter " + format_number(p);
      return std::nullopt;
    }
    // g is linear: after one Newton step it is at its rounding level, eps times the size of its terms
    const double g_scale = row_x.cwiseAbs().dot(x.cwiseAbs()) + std::abs(row_p * p) + std::abs(target);
    const double tol_abs = tolerance * (1 + x.lpNorm<Eigen::Infinity>());
    const bool converged = r <= tol_abs && std::abs(g) <= 1e-12 * (1 + g_scale);
    if (it == 1) first = r;
    if (!converged && (it >= max_iterations || r > 1e3 * first)) {
      why = (it >= max_iterations ? "not converged in " + std::to_string(it) + " iterations"
                                  : "residual diverging at iteration " + std::to_string(it)) +
            ", |F|_inf = " + format_number(r) + " at parameter " + format_number(p);
      account();
      return std::nullopt;
    }
    if (converged) {  // the tangent z: [G_x G_p; row] z = e_{n+1}, z / |z|_w
      const std::optional<Eigen::VectorXd> z = lin->solve(Eigen::VectorXd::Zero(n), 1, forcing.tangent, why);
      account();
      if (!z) return std::nullopt;
      const double norm = std::sqrt(weight * z->head(n).squaredNorm() + (*z)[n] * (*z)[n]);
      return BranchState{std::move(x), p, z->head(n) / norm, (*z)[n] / norm, it, r};
    }
    // The forcing's floor from the stricter of the two acceptance tests: |G| to tol_abs, g to its rounding level.
    const double g_norm = std::hypot(G.norm(), g);
    eta = shooting_forcing_term(eta, g_norm, previous_norm, std::min(tol_abs, 1e-12 * (1 + g_scale)),
                                forcing.forcing_max, it == 0);
    previous_norm = g_norm;
    const std::optional<Eigen::VectorXd> step = lin->solve(-G, -g, eta, why);
    if (!step) {
      account();
      return std::nullopt;
    }
    x += step->head(n);
    p += (*step)[n];
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
  const CorrectorWork before = branch.work();
  BranchTracer tracer(branch, options, start_tangent, start_p);
  ContinuationResult result = tracer.trace(guess);
  result.unknowns = branch.unknowns();
  result.factorisations = branch.work().factorisations - before.factorisations;
  result.gmres_products = branch.work().products - before.products;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - run_start).count();
  return result;
}

}  // namespace delayspec::continuation_detail
