#pragma once
// Periodic orbits by Newton on the discrete periodic problem (design.md 1.6).
//
// Unknowns: the K states of one stroboscopic map, x = (u_0, ..., u_{K-1}), u_l = y(l h), stacked
// (dimension d K), extended periodically: u_{l+K} = u_l. The orbit satisfies, for every step
// l = 0 .. K-1 (times t_l = (l mod K_1) h, the grid phase of StroboscopicMap),
//
//   F_l(x) = u_{l+1} - S_l(u_l, w0_l, w1_l) = 0,
//   w0_l = (1 - theta) u_{l-m} + theta u_{l-m-1}     (delayed value at the step start)
//   w1_l = (1 - theta) u_{l-m+1} + theta u_{l-m}     (delayed value at the step end)
//
// where S_l is one full step of the stepper (TrapezoidStepper::step: events included, whatever
// the stepper's options say) and all indices are taken mod K. The Jacobian is sparse: block row
// l has I at u_{l+1}, -P_l at u_l and the delayed blocks -(1-theta) Q_l, -theta Q_l, -(1-theta)
// R_l, -theta R_l at u_{l-m}, u_{l-m-1}, u_{l-m+1}, u_{l-m} (P, Q, R: the step map of step l;
// blocks landing on the same column are added). It is factored with UMFPACK (sparse_lu.hpp).
//
// A periodic point of the stroboscopic map P(U) = U is exactly such a periodic sequence (and
// back): U is the last M + 1 states, U = (u_{-M}, ..., u_0) with u_{-j} = u_{K-j}.
//
// Newton: x <- x + lambda s with J(x) s = -F(x); lambda = 1 unless the full step does not
// reduce |F|_2 (or leaves the stepper's domain), then halved up to 30 times (a safeguard for
// poor guesses; near the orbit every step is full and convergence is quadratic for a smooth
// residual). Converged when |F|_inf <= tolerance (1 + |x|_inf).
//
// Errors: BadInput for a bad option or a guess of the wrong size; NumericalFailure (with the
// iterations and the residual) when Newton does not converge within max_iterations, stalls
// (no step reduces the residual: e.g. a tolerance below rounding), or the Jacobian is singular.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "delayspec/errors.hpp"
#include "delayspec/periodic_orbit.hpp"
#include "delayspec/detail/sparse_lu.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec {

struct OrbitByNewtonOptions {
  double tolerance = 1e-12;  // accept |F|_inf <= tolerance (1 + |x|_inf)
  int max_iterations = 30;   // Newton steps (linear solves) before giving up
  // Newton steps taken even when the guess meets the tolerance. A guess from a nearby parameter
  // (a curve's last point) can meet it while off by the parameter change times the orbit's
  // sensitivity (|F| is one step's residual, the orbit's error up to K times more); one step
  // leaves O(|F|^2). `boundary` takes 1: without it its grazing test function was noisy at 5e-10.
  int min_iterations = 0;
};

// The discrete periodic problem of one stroboscopic map of `map` (its stepper and grid).
template <class Map>
class PeriodicOrbitProblem {
 public:
  static constexpr int D = Map::D;
  static constexpr int DW = Map::DW;  // D, or D n with n delays (model.hpp)
  using V = Vec<D>;
  using W = Vec<DW>;

  explicit PeriodicOrbitProblem(const Map& map) : map_(map), grid_(map.grid()) {}

  long unknowns() const { return static_cast<long>(D) * grid_.K; }
  const HistoryGrid& grid() const { return grid_; }

  // F(x); when jacobian is non-null it receives dF/dx (unknowns() x unknowns(), compressed); when
  // step_maps is, the K step maps (P_l, Q_l, R_l) that make it up, for a matrix-free product
  // (detail/condensed_bordered.hpp).
  Eigen::VectorXd residual(const Eigen::VectorXd& x, Eigen::SparseMatrix<double>* jacobian = nullptr,
                           std::vector<StepMap<D, DW>>* step_maps = nullptr) const {
    check_size(x);
    const long K = grid_.K, M = grid_.M;
    auto u = [&](long l) { return x.segment<D>(D * wrap(l)); };
    auto slot = [&](long i) { return u(i - M); };  // delay_tap's numbering: slot M + l = u_l
    // Each delay's position (m_i, theta_i) and its column block of Q and R: one, or grid.delays.
    std::vector<HistoryGrid::DelayPosition> taps = grid_.delays;
    if (taps.empty()) taps.push_back({grid_.tau, grid_.m, grid_.theta});
    Eigen::VectorXd F(unknowns());
    std::vector<Eigen::Triplet<double>> triplets;
    if (jacobian) triplets.reserve(static_cast<size_t>(K) * D * D * (1 + 6 * taps.size()) + K * D);
    StepMap<D, DW> one_map;
    if (step_maps) step_maps->resize(static_cast<size_t>(K));
    for (long l = 0; l < K; ++l) {
      StepMap<D, DW>& map = step_maps ? (*step_maps)[static_cast<size_t>(l)] : one_map;
      const DelayTap<W> tap = grid_.template delay_taps<D, W>(l, slot);
      const V next = map_.step(l, tap, V(u(l)), map);
      F.segment<D>(D * l) = u(l + 1) - next;  // F_l = u_{l+1} - S_l(u_l, w0_l, w1_l)
      if (!jacobian) continue;
      add_block(triplets, l, l + 1, Mat<D>::Identity());
      add_block(triplets, l, l, -map.P);
      for (size_t i = 0; i < taps.size(); ++i) {  // w0_i = (1 - theta_i) u_{l-m_i} + theta_i u_{l-m_i-1}, w1_i one later
        const long m = taps[i].m;
        const double theta = taps[i].theta, c0 = 1 - theta;
        const Mat<D> Q = map.Q.template middleCols<D>(static_cast<long>(i) * D);
        const Mat<D> R = map.R.template middleCols<D>(static_cast<long>(i) * D);
        add_block(triplets, l, l - m, -c0 * Q);
        add_block(triplets, l, l - m + 1, -c0 * R);
        if (theta != 0) {
          add_block(triplets, l, l - m - 1, -theta * Q);
          add_block(triplets, l, l - m, -theta * R);
        }
      }
    }
    if (jacobian) {
      jacobian->resize(unknowns(), unknowns());
      jacobian->setFromTriplets(triplets.begin(), triplets.end());  // duplicates are summed
      jacobian->makeCompressed();
    }
    return F;
  }

  // The history U = (u_{-M}, ..., u_0) of the stroboscopic map (oldest block first).
  Eigen::VectorXd history(const Eigen::VectorXd& x) const {
    check_size(x);
    Eigen::VectorXd U(grid_.dimension(D));
    for (long j = 0; j <= grid_.M; ++j) U.segment<D>(D * j) = x.segment<D>(D * wrap(j - grid_.M));
    return U;
  }

  // The sequence x of one map started from history U: u_l = state after l steps, l = 0 .. K-1.
  Eigen::VectorXd sequence_from_history(const Eigen::VectorXd& U) const {
    std::vector<V> trajectory;
    map_.apply(U, nullptr, &trajectory);
    Eigen::VectorXd x(unknowns());
    for (long l = 0; l < grid_.K; ++l) x.segment<D>(D * l) = trajectory[static_cast<size_t>(l)];
    return x;
  }

 private:
  long wrap(long l) const {
    const long K = grid_.K;
    return ((l % K) + K) % K;
  }
  void check_size(const Eigen::VectorXd& x) const {
    if (x.size() != unknowns())
      throw BadInput("periodic orbit problem: sequence has " + std::to_string(x.size()) +
                     " entries, expected d K = " + std::to_string(unknowns()));
  }
  void add_block(std::vector<Eigen::Triplet<double>>& triplets, long row_block, long col_block,
                 const Mat<D>& block) const {
    const long r0 = D * row_block, c0 = D * wrap(col_block);
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j)
        if (block(i, j) != 0) triplets.emplace_back(static_cast<int>(r0 + i), static_cast<int>(c0 + j), block(i, j));
  }

  const Map& map_;
  HistoryGrid grid_;
};

// Newton from the sequence guess x (e.g. PeriodicOrbitProblem::sequence_from_history of a
// simulated history). Returns the orbit with its history, |P(U) - U|_inf recomputed by one
// application of the map, and the Newton record (iterations, residual history, step fractions,
// Jacobian statistics). `maps` is left for the caller (how many periods the guess took).
template <class Map>
PeriodicOrbit orbit_by_newton(const Map& map, Eigen::VectorXd x, const OrbitByNewtonOptions& opt = {}) {
  if (!(opt.tolerance > 0) || !std::isfinite(opt.tolerance))
    throw BadInput("`orbit_tolerance = " + format_number(opt.tolerance) + "`: must be > 0 and finite");
  if (opt.max_iterations < 1)
    throw BadInput("`orbit_max_iterations = " + std::to_string(opt.max_iterations) + "`: must be >= 1");
  PeriodicOrbitProblem<Map> problem(map);
  if (x.size() != problem.unknowns())
    throw BadInput("orbit by Newton: guess has " + std::to_string(x.size()) + " entries, expected " +
                   std::to_string(problem.unknowns()));
  if (!x.allFinite()) throw NumericalFailure("orbit by Newton: the guess is not finite (did the simulation diverge?)");

  PeriodicOrbit orbit;
  orbit.method = OrbitFoundBy::newton;
  Eigen::SparseMatrix<double> J;
  Eigen::VectorXd F = problem.residual(x, &J);
  double r = F.lpNorm<Eigen::Infinity>();
  orbit.newton_residuals.push_back(r);
  auto failure = [&](const std::string& why) {
    return NumericalFailure("orbit by Newton: " + why + " after " + std::to_string(orbit.newton_iterations) +
                            " iterations, |F|_inf = " + format_number(r) + " (tolerance " +
                            format_number(opt.tolerance * (1 + x.lpNorm<Eigen::Infinity>())) + ")");
  };
  const auto converged = [&] { return r <= opt.tolerance * (1 + x.lpNorm<Eigen::Infinity>()); };
  while (orbit.newton_iterations < opt.min_iterations || !converged()) {
    if (!std::isfinite(r)) throw failure("non-finite residual");
    if (orbit.newton_iterations >= opt.max_iterations) throw failure("not converged");
    SparseLU lu = [&] {
      try {
        return SparseLU(J);
      } catch (const NumericalFailure& e) {
        throw failure(std::string("Jacobian factorisation failed (") + e.what() + ")");
      }
    }();
    orbit.jacobian_reciprocal_condition = lu.reciprocal_condition();
    orbit.jacobian_nonzeros = J.nonZeros();
    orbit.factor_nonzeros = lu.factor_nonzeros();
    const Eigen::VectorXd s = lu.solve(-F);  // J s = -F
    ++orbit.newton_iterations;
    // Full step unless it fails to reduce |F|_2; then halve (at most 30 times).
    bool accepted = false;
    double lambda = 1;
    for (int halvings = 0; halvings <= 30 && !accepted; ++halvings, lambda *= 0.5) {
      Eigen::VectorXd trial = x + lambda * s;
      Eigen::SparseMatrix<double> J_trial;
      Eigen::VectorXd F_trial;
      try {
        F_trial = problem.residual(trial, &J_trial);
      } catch (const NumericalFailure&) {
        continue;  // the stepper could not take a step from this trial: shorten
      }
      const double r_trial = F_trial.lpNorm<Eigen::Infinity>();
      if (F_trial.norm() < F.norm()) {  // |F|_2 decreases: s is a descent direction for |F|_2^2
        x.swap(trial);
        F.swap(F_trial);
        J = std::move(J_trial);
        r = r_trial;
        accepted = true;
        orbit.newton_step_fractions.push_back(lambda);
        orbit.newton_residuals.push_back(r);
      }
    }
    if (!accepted && converged()) break;  // a step asked for by min_iterations, from round-off already
    if (!accepted) throw failure("stalled (no step along the Newton direction reduces the residual)");
  }
  orbit.history = problem.history(x);
  orbit.residual = (map.apply(orbit.history) - orbit.history).template lpNorm<Eigen::Infinity>();
  return orbit;
}

}  // namespace delayspec
