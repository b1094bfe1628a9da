#pragma once
// What both branches of periodic orbits share (periodic_branch.hpp: a forced orbit, unknowns x;
// autonomous_branch.hpp: an orbit of unknown period, unknowns (x, T)): the corrected point with
// its tangent, the bordered Newton corrector, the parameter derivative by differences, the
// leading multipliers of a point, the orbit's extremes. Part of continuation.hpp's
// implementation (its header states the mathematics); not an interface.
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "delayspec/continuation.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/detail/sparse_lu.hpp"

namespace delayspec::continuation_detail {

// A corrected point of a branch with the unit tangent there (weighted norm).
struct BranchState {
  Eigen::VectorXd x;
  double p = 0;
  Eigen::VectorXd tx;
  double tp = 0;
  int iterations = 0;
  double residual = 0;
};

// Adds the time from construction to destruction to `seconds`.
struct ScopedSeconds {
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  double& seconds;
  explicit ScopedSeconds(double& s) : seconds(s) {}
  ~ScopedSeconds() { seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); }
};

// Newton from (x, p) on G(x, p) = 0 and  row_x . x + row_p p = target:
//   [ G_x    G_p   ] [dx]     [ G ]
//   [ row_x  row_p ] [dp] = - [ g ],   g = row_x . x + row_p p - target,
// one sparse LU per iteration. `linearise(x, p, G, G_x, G_p, why)` gives G and its derivatives,
// or false and why. Converged when |G|_inf <= tolerance (1 + |x|_inf) and g is at its rounding
// level; then the tangent solves the same matrix with e_{n+1}, normalised in the norm
// weight |z_x|^2 + z_p^2. Returns nullopt and the reason on failure: not converged in
// max_iterations, diverging (the residual 1e3 times above the one after the first step: not any
// growth, since near grazing the discrete problem is only piecewise smooth and an iterate may
// raise |G| before converging, and the start may have |G| = 0 with the constraint violated), a
// singular matrix, a residual that cannot be formed.
template <class Linearise>
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

// G_p at p by the central difference (G(p + delta) - G(p - delta)) / (2 delta), delta = eps^(1/3)
// max(|p|, scale) (continuation.hpp: why that is enough). `residual_at(q)` is G at q and throws
// BadInput where the model rejects q: at a bound of the key's range (milling's depth from 0: p -
// delta = -6e-9 is rejected) the one-sided second-order stencil on the side the model accepts,
// (-3 G(p) + 4 G(p + s) - G(p + 2 s)) / (2 s), s = +-delta: the same order, and truncation 2x
// the central one's. Neither side accepted: the model's reason (BadInput) passes through.
template <class ResidualAt>
Eigen::VectorXd parameter_derivative(const ResidualAt& residual_at, double p, const Eigen::VectorXd& G, double scale) {
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

// The leading multipliers of a monodromy with the options' nev. A pair failing the residual gate
// is nearly always one of the smallest requested (|mu| ~ 1e-7 on a nearly rank-deficient
// monodromy, far below anything that crosses the circle): retried with one multiplier fewer,
// down to one; the point has then fewer multipliers.
template <class Operator>
std::vector<std::complex<double>> leading_multipliers(const Operator& monodromy, FloquetOptions floquet,
                                                      double& seconds) {
  const ScopedSeconds timer(seconds);
  for (;;) {
    try {
      return floquet_multipliers(monodromy, floquet).multipliers;
    } catch (const NumericalFailure&) {
      if (floquet.nev <= 1) throw;
      --floquet.nev;
    }
  }
}

// The extremes per component of the K states x = (u_0, ..., u_{K-1}), each of dimension D.
template <int D>
OrbitMeasures state_extremes(const Eigen::VectorXd& x, long K) {
  OrbitMeasures m;
  const Eigen::Map<const Eigen::Matrix<double, D, Eigen::Dynamic>> states(x.data(), D, K);
  for (int i = 0; i < D; ++i) {
    m.max.push_back(states.row(i).maxCoeff());
    m.min.push_back(states.row(i).minCoeff());
  }
  return m;
}

}  // namespace delayspec::continuation_detail
