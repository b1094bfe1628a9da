#pragma once
// Orbits of unknown period at large N: nested Newton-Krylov shooting on (U, T) (issue 35, item 3).
//
// find_autonomous_orbit (autonomous_orbit.hpp) solves for all K states of the period and T by
// sparse-LU Newton; with a long delay the LU fills in, so N in the thousands is practical and
// 10^5 is not. Here, as orbit_shooting.hpp does for a forced orbit, the unknowns are the history
// U (the states over one delay) and T, the period's map P_T of the scaled problem
// (autonomous_orbit.hpp: K steps of h = 1 / K at time scale s = t / T) is applied matrix-free,
// and the levels are nested:
//
//   G(U, T) = P_T(U) - U = 0,   g(U) = c . (U - U_ref) = 0,
//
// c the unit derivative of the reference history U_ref (the level's start) along its slots
// (central differences, one-sided at the ends): the integral phase condition over the history
// window, which fixes the time shift the orbit is free in. Newton on
//
//   [ M_U - I   P_T ] [dU]     [ G ]
//   [ c^T       0   ] [dT] = - [ g ],
//
// M_U the monodromy at U (the step maps recorded by the evaluation of G, applied matrix-free),
// P_T = (P_{T + d}(U) - P_T(U)) / d with d = sqrt(eps) T (one more map per Newton step; its O(d)
// error makes Newton contract by ~1e-8 per step instead of quadratically, and never moves the
// solution, which is G = g = 0), solved by GMRES with the Eisenstat-Walker forcing terms of
// orbit_shooting.hpp; the step is halved while |(G, g)|_2 does not decrease. Converged when
// |G|_inf <= tolerance (1 + |U|_inf), shooting's test.
//
// The history's length. The delays in steps, tau_i K / T, move with T, and with them the slots
// the history needs (M + 1). The grid keeps M fixed at what T_0 (1 - margin) needs, margin = 0.25,
// every tap where it falls inside (slots beyond the longest tap are carried as the orbit's
// earlier states: still a fixed point of P_T). A Newton iterate whose period leaves [T_0 (1 -
// margin), ...) is a step the line search halves.
//
// Levels. K_L = K = round(N T_guess / tau_max), exactly find_autonomous_orbit's, so that both
// solve the same discrete problem; K_{i-1} = round(K_i / refinement) while >= K_coarse (the K of
// N = coarse_N; one level, sparse LU alone, when N < refinement coarse_N); the coarsest by
// find_autonomous_orbit (sparse LU, from the simulated guess);
// each finer level from the coarser orbit's states prolonged (prolong_periodic_sequence) and its
// period. The orbit returned carries the sequence of the last evaluation and the history of the
// standard grid (autonomous_orbit_map: the multipliers' map).
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "delayspec/autonomous_orbit.hpp"
#include "delayspec/gmres.hpp"
#include "delayspec/monodromy.hpp"
#include "delayspec/orbit_shooting.hpp"
#include "delayspec/periodic_orbit.hpp"

namespace delayspec {

// The finer levels' Newton-Krylov iteration (the coarsest level's is the AutonomousOrbitOptions').
struct AutonomousShootingOptions {
  OrbitByShootingOptions shooting;
  int refinement = 8;    // K_i / K_{i-1}
  double margin = 0.25;  // the period may fall to T_0 (1 - margin) within a level (header)
};

namespace detail {

// The unit derivative of a history along its slots (d entries per slot).
inline Eigen::VectorXd history_phase_row(const Eigen::VectorXd& U, int d) {
  const long slots = U.size() / d;
  Eigen::VectorXd c(U.size());
  for (long i = 0; i < slots; ++i) {
    const long a = std::max(0L, i - 1), b = std::min(slots - 1, i + 1);
    c.segment(d * i, d) = (U.segment(d * b, d) - U.segment(d * a, d)) / static_cast<double>(b - a);
  }
  const double norm = c.norm();
  if (!(norm > 0)) throw NumericalFailure("autonomous shooting: the history is constant (an equilibrium?)");
  return c / norm;
}

// One level's Newton-Krylov iteration on (U, T) (header): the residual, the bordered GMRES
// direction, the line search; the grid's history keeps M + 1 slots.
template <class Model>
class PeriodShooter {
 public:
  static constexpr int D = Model::d;
  using Map = StroboscopicMap<TimeScaled<Model>>;

  PeriodShooter(const Model& model, int K, int M, const Eigen::VectorXd& U_ref, const OrbitByShootingOptions& opt,
                const StepOptions& step)
      : model_(model), K_(K), M_(M), opt_(opt), step_(step), c_(history_phase_row(U_ref, D)), U_ref_(U_ref) {}

  Map map(double T) const { return scaled_map(model_, T, K_, step_, M_); }
  double phase(const Eigen::VectorXd& U) const { return c_.dot(U - U_ref_); }

  // G = P_T(U) - U with the step maps and states of the evaluation in lin; false where it cannot
  // be formed (a period that needs more slots, a step that fails, a value not finite).
  bool evaluate(const Eigen::VectorXd& U, double T, Eigen::VectorXd& G) {
    try {
      const Map m = map(T);
      G = m.apply(U, &lin.maps, &lin.states) - U;
      grid_ = m.grid();
      return G.allFinite();
    } catch (const NumericalFailure&) {
      return false;
    } catch (const BadInput&) {
      return false;
    }
  }

  // The Newton step (dU, dT) of [M_U - I, P_T; c^T, 0] = -(G, g) to GMRES' tolerance eta, M_U
  // from the step maps and grid of the last evaluation (at U, T); P_T by a forward difference
  // (header).
  // NumericalFailure's reason in `why` when P_T cannot be formed or GMRES makes no progress.
  bool direction(const Eigen::VectorXd& U, double T, const Eigen::VectorXd& G, double eta, Eigen::VectorXd& step,
                 std::string& why) {
    const double delta = std::sqrt(std::numeric_limits<double>::epsilon()) * T;
    Eigen::VectorXd PT;
    try {
      PT = (map(T + delta).apply(U) - (G + U)) / ((T + delta) - T);
    } catch (const std::exception& e) {
      why = std::string("the period's derivative cannot be formed (") + e.what() + ")";
      return false;
    }
    const long n = U.size();
    Eigen::VectorXd rhs(n + 1);
    rhs << -G, -phase(U);
    Monodromy<D, delayed_rows<Model>> monodromy(grid_, std::move(lin.maps));
    const GmresResult s = gmres(
        [&](const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& y) {
          y.resize(n + 1);
          monodromy.perform_op(v.data(), y.data());
          y.head(n) -= v.head(n);
          y.head(n) += v[n] * PT;
          y[n] = c_.dot(v.head(n));
        },
        rhs, GmresOptions{eta, opt_.gmres_restart, opt_.gmres_max_iterations}, &basis_);
    lin.maps = std::move(monodromy).take_step_maps();
    if (!(s.relative_residual < 1)) {
      why = "GMRES made no progress on the bordered shooting system (relative residual " +
            format_number(s.relative_residual) + ")";
      return false;
    }
    step = s.x;
    return true;
  }

  // The full step unless |(G, g)|_2 does not decrease; then halved, at most 30 times. Updates U,
  // T, G (and lin); false when no fraction reduces it.
  bool line_search(const Eigen::VectorXd& step, Eigen::VectorXd& U, double& T, Eigen::VectorXd& G) {
    const long n = U.size();
    const double norm = std::hypot(G.norm(), phase(U));
    double lambda = 1;
    for (int halvings = 0; halvings <= 30; ++halvings, lambda *= 0.5) {
      Eigen::VectorXd trial = U + lambda * step.head(n), G_trial;
      const double T_trial = T + lambda * step[n];
      if (T_trial > 0 && evaluate(trial, T_trial, G_trial) && std::hypot(G_trial.norm(), phase(trial)) < norm) {
        U.swap(trial), G.swap(G_trial), T = T_trial;
        return true;
      }
    }
    return false;
  }

  OrbitLinearisation<D, delayed_rows<Model>> lin;  // of the last evaluation

 private:
  const Model& model_;
  int K_, M_;
  const OrbitByShootingOptions& opt_;
  const StepOptions& step_;
  Eigen::VectorXd c_, U_ref_;
  Eigen::MatrixXd basis_;  // GMRES' workspace, kept across Newton steps
  HistoryGrid grid_;       // of the last evaluation
};

// One level: Newton-Krylov on (U, T) from the sequence x (K states) and T (header).
template <class Model>
AutonomousOrbit shoot_autonomous_level(const Model& model, int K, const Eigen::VectorXd& x, double T,
                                       const AutonomousShootingOptions& o, const StepOptions& step) {
  using Map = StroboscopicMap<TimeScaled<Model>>;
  constexpr int D = Model::d;
  const OrbitByShootingOptions& opt = o.shooting;
  const int M = make_grid_with_steps(delays_of(TimeScaled<Model>{model, T * (1 - o.margin)}), 1.0, K).M;
  Eigen::VectorXd U = PeriodicOrbitProblem<Map>(scaled_map(model, T, K, step, M)).history(x);
  PeriodShooter<Model> shooter(model, K, M, U, opt, step);
  AutonomousOrbit out;
  Eigen::VectorXd G;
  double r = NAN;
  auto failure = [&](const std::string& why) {
    return NumericalFailure("autonomous orbit by shooting (K = " + std::to_string(K) + " steps per period): " + why +
                            " after " + std::to_string(out.newton_iterations) + " Newton iterations, |P(U) - U|_inf = " +
                            format_number(r) + ", period reached " + format_number(T));
  };
  if (!shooter.evaluate(U, T, G)) throw failure("the map cannot be evaluated at the starting history");
  double eta = opt.forcing_max, previous_norm = NAN;
  for (;;) {
    r = G.lpNorm<Eigen::Infinity>();
    out.newton_residuals.push_back(r);
    out.periods.push_back(T);
    const double tol_abs = opt.tolerance * (1 + U.lpNorm<Eigen::Infinity>());
    if (r <= tol_abs && std::abs(shooter.phase(U)) <= 1e-12 * (1 + U.lpNorm<Eigen::Infinity>())) break;
    if (out.newton_iterations >= opt.max_iterations) throw failure("not converged");
    const double g_norm = std::hypot(G.norm(), shooter.phase(U));
    eta = shooting_forcing_term(eta, g_norm, previous_norm, tol_abs, opt.forcing_max, out.newton_iterations == 0);
    Eigen::VectorXd s;
    std::string why;
    if (!shooter.direction(U, T, G, eta, s, why)) throw failure(why);
    ++out.newton_iterations;
    if (!shooter.line_search(s, U, T, G))
      throw failure("stalled (no step along the Newton direction reduces the residual)");
    previous_norm = g_norm;
  }
  // The sequence from the last evaluation (at U), the history on the standard grid.
  Eigen::VectorXd sequence(static_cast<long>(D) * K);
  for (long l = 0; l < K; ++l) sequence.segment<D>(D * l) = shooter.lin.states[static_cast<size_t>(l)];
  const Map standard = scaled_map(model, T, K, step);
  out.period = T;
  out.grid = standard.grid();
  out.sequence = sequence;
  out.history = PeriodicOrbitProblem<Map>(standard).history(sequence);
  out.residual = r;
  return out;
}

}  // namespace detail

// The orbit near the simulated guess by nested shooting (header). Errors as find_autonomous_orbit,
// and NumericalFailure naming the level when a level's Newton-Krylov iteration fails.
template <class Model>
AutonomousOrbit find_autonomous_orbit_by_shooting(const Model& model, const AutonomousOrbitOptions& o,
                                                  const AutonomousShootingOptions& so = {}) {
  const int K = autonomous_steps_per_period(model, o);
  if (o.coarse_N < 1) throw BadInput("`orbit_coarse_N = " + std::to_string(o.coarse_N) + "`: must be >= 1");
  const int K_coarse = std::max(1, static_cast<int>(std::lround(static_cast<double>(K) * o.coarse_N / o.N)));
  if (so.refinement < 2) throw BadInput("autonomous shooting: refinement must be >= 2");
  std::vector<int> Ks{K};
  while (Ks.back() / so.refinement >= K_coarse && Ks.back() / so.refinement >= 4)
    Ks.push_back(static_cast<int>(std::lround(static_cast<double>(Ks.back()) / so.refinement)));
  std::reverse(Ks.begin(), Ks.end());
  AutonomousOrbit orbit = find_autonomous_orbit_with_steps(model, o, Ks.front());
  int iterations = orbit.newton_iterations;
  for (size_t i = 1; i < Ks.size(); ++i) {
    const Eigen::VectorXd x = prolong_periodic_sequence(orbit.sequence, Model::d, Ks[i]);
    orbit = detail::shoot_autonomous_level(model, Ks[i], x, orbit.period, so, o.step);
    orbit.method = AutonomousOrbitMethod::shooting;
    iterations += orbit.newton_iterations;
  }
  orbit.newton_iterations = iterations;
  return orbit;
}

}  // namespace delayspec
