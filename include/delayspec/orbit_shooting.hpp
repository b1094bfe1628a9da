#pragma once
// Periodic orbits at large N by Newton-Krylov shooting on the stroboscopic map, started from the
// orbit at a coarser N (nested iteration). Finds unstable orbits too.
//
// Shooting. A periodic point of the map solves G(U) = P(U) - U = 0, U in R^n, n = d (M + 1).
// Newton: (M_U - I) s = -G(U), U <- U + lambda s, where M_U is the monodromy at U. Evaluating
// P(U) records the step maps along the way (StroboscopicMap::apply), so M_U costs nothing extra
// and is applied matrix-free (O(K d^2) per product); the linear system is solved by GMRES
// (gmres.hpp) only as accurately as Newton needs (Eisenstat-Walker "choice 2" forcing terms):
//     eta_0 = eta_max,  eta_k = min(eta_max, max(0.9 (|G_k| / |G_{k-1}|)^2, 0.9 eta_{k-1}^2 if > 0.1)),
// never below 0.5 tol_abs / |G_k|_2 (solving further than the final tolerance is wasted). A full
// step is taken unless it fails to reduce |G|_2 (or the stepper cannot take a step there); then it
// is halved, at most 30 times. Converged when |G|_inf <= tolerance (1 + |U|_inf), the same test as
// simulation and sparse-LU Newton. Each Newton step costs one map evaluation (the nonlinear
// steps: the dominant cost) plus a few GMRES products (~ 1 % of a map each).
//
// Nested iteration. Levels N_0 < N_1 < ... < N_L = N, N_{i-1} ~ N_i / 8 (a valid grid: a multiple
// of p when tau / T = p / q), down to the last one >= coarse_N, then N_0 = coarse_N itself (the
// first valid N from it) unless that exceeds half N_1. The coarsest orbit comes from
// `guess_periods` maps simulated from the constant initial history, then Newton at N_0 (shooting,
// sparse LU if that fails: CoarseOrbitMethod below); each finer level starts from the coarser orbit prolonged in time
// (prolong_periodic_sequence). The prolonged guess is O(h_{i-1}^2) from the level's orbit, so a
// level needs one or two Newton steps and the whole costs about 1 + 1/8 + 1/64 + ... of the
// finest level's map evaluations per step, instead of the hundreds of periods simulation needs.
//
// The orbit's linearisation. The last evaluation is at the returned history, so its step maps
// and states (the monodromy and the trajectory at the orbit) are handed back when asked: a caller
// computing multipliers or contacts does not evaluate the map again.
//
// Errors: BadInput for bad options or a history of the wrong size; NumericalFailure naming the
// level, the iterations and |P(U) - U|_inf when Newton does not converge or stalls, or when GMRES
// makes no progress (M - I singular: a multiplier at +1, a fold).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "delayspec/errors.hpp"
#include "delayspec/gmres.hpp"
#include "delayspec/monodromy.hpp"
#include "delayspec/orbit_newton.hpp"
#include "delayspec/orbit_simulation.hpp"
#include "delayspec/periodic_orbit.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec {

struct OrbitByShootingOptions {
  double tolerance = 1e-12;        // accept |P(U) - U|_inf <= tolerance (1 + |U|_inf)
  int max_iterations = 30;         // Newton steps per level
  double forcing_max = 1e-4;       // eta_max of the Eisenstat-Walker forcing terms (below)
  int gmres_restart = 40;          // GMRES basis size per cycle
  int gmres_max_iterations = 400;  // GMRES products per Newton step
};

// What the last map evaluation of a solve saw: the step maps (the monodromy at the orbit) and
// the K + 1 states u_0 at t = 0, h, ..., K h.
template <int D, int DW = D>
struct OrbitLinearisation {
  std::vector<StepMap<D, DW>> maps;
  std::vector<Vec<D>> states;
};

// GMRES' relative tolerance for the next Newton step (header): Eisenstat-Walker choice 2 with its
// safeguard from the previous eta and the residual norms |G_k|_2 = g_norm, |G_{k-1}|_2 =
// previous_norm (eta_max at the first step), never below 0.5 tol_abs / |G_k|_2 (|r|_inf <= |r|_2
// <= eta |G|_2 is then enough for the final test) nor GMRES' own rounding floor, 1e-13.
inline double shooting_forcing_term(double eta, double g_norm, double previous_norm, double tol_abs,
                                    double forcing_max, bool first) {
  if (!first) {
    const double ratio = g_norm / previous_norm;
    double next = 0.9 * ratio * ratio;
    if (0.9 * eta * eta > 0.1) next = std::max(next, 0.9 * eta * eta);
    eta = std::min(next, forcing_max);
  }
  return std::max({eta, 0.5 * tol_abs / g_norm, 1e-13});
}

// Newton-Krylov shooting from history U (header). `at_orbit`, when given, receives the step maps
// and states of the map at the returned history.
template <class Map>
PeriodicOrbit orbit_by_shooting(const Map& map, Eigen::VectorXd U, const OrbitByShootingOptions& opt,
                                OrbitLinearisation<Map::D, Map::DW>* at_orbit = nullptr) {
  constexpr int D = Map::D;
  if (!(opt.tolerance > 0) || !std::isfinite(opt.tolerance))
    throw BadInput("`orbit_tolerance = " + format_number(opt.tolerance) + "`: must be > 0 and finite");
  if (opt.max_iterations < 1)
    throw BadInput("`orbit_max_iterations = " + std::to_string(opt.max_iterations) + "`: must be >= 1");
  if (!(opt.forcing_max > 0 && opt.forcing_max < 1))
    throw BadInput("shooting: forcing_max = " + format_number(opt.forcing_max) + " must be in (0, 1)");
  if (U.size() != map.dimension())
    throw BadInput("orbit by shooting: history has " + std::to_string(U.size()) + " entries, expected " +
                   std::to_string(map.dimension()));
  if (!U.allFinite()) throw NumericalFailure("orbit by shooting: the starting history is not finite");

  PeriodicOrbit orbit;
  orbit.method = OrbitFoundBy::shooting;
  OrbitLinearisation<D, Map::DW> lin;
  // G = P(X) - X with the step maps and states of this evaluation in `lin`; false when the
  // stepper cannot step from X or the result is not finite.
  auto evaluate = [&](const Eigen::VectorXd& X, Eigen::VectorXd& G) {
    try {
      G = map.apply(X, &lin.maps, &lin.states) - X;
    } catch (const NumericalFailure&) {
      return false;
    }
    return G.allFinite();
  };
  Eigen::VectorXd G;
  Eigen::MatrixXd basis;  // GMRES' workspace, kept across Newton steps
  double r = NAN;
  auto failure = [&](const std::string& why) {
    return NumericalFailure("orbit by shooting (N = " + std::to_string(map.grid().N) + "): " + why + " after " +
                            std::to_string(orbit.newton_iterations) +
                            " Newton iterations, |P(U) - U|_inf = " + format_number(r) + " (tolerance " +
                            format_number(opt.tolerance * (1 + U.lpNorm<Eigen::Infinity>())) + ")");
  };
  if (!evaluate(U, G)) throw failure("the map cannot be evaluated at the starting history");
  r = G.lpNorm<Eigen::Infinity>();
  orbit.newton_residuals.push_back(r);
  double eta = opt.forcing_max, previous_norm = NAN;
  while (!(r <= opt.tolerance * (1 + U.lpNorm<Eigen::Infinity>()))) {
    if (orbit.newton_iterations >= opt.max_iterations) throw failure("not converged");
    const double g_norm = G.norm();
    eta = shooting_forcing_term(eta, g_norm, previous_norm, opt.tolerance * (1 + U.lpNorm<Eigen::Infinity>()),
                                opt.forcing_max, orbit.newton_iterations == 0);
    // (M - I) s = -G with M the monodromy at U (the step maps of the evaluation of G); the maps'
    // storage goes back to `lin` for the next evaluation, the Krylov basis stays in `basis`.
    Monodromy<D, Map::DW> monodromy(map.grid(), std::move(lin.maps));
    const GmresResult step = gmres(
        [&](const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::VectorXd& y) {
          monodromy.perform_op(x.data(), y.data());
          y -= x;  // y = (M - I) x
        },
        -G, GmresOptions{eta, opt.gmres_restart, opt.gmres_max_iterations}, &basis);
    lin.maps = std::move(monodromy).take_step_maps();
    orbit.linear_iterations += step.iterations;
    ++orbit.newton_iterations;
    if (!(step.relative_residual < 1))
      throw failure("GMRES made no progress on (M - I) s = -G (relative residual " +
                    format_number(step.relative_residual) + "; a multiplier at +1?)");
    // Full step unless it fails to reduce |G|_2; then halve (at most 30 times).
    bool accepted = false;
    double lambda = 1;
    Eigen::VectorXd trial, G_trial;
    for (int halvings = 0; halvings <= 30 && !accepted; ++halvings, lambda *= 0.5) {
      trial = U + lambda * step.x;
      accepted = evaluate(trial, G_trial) && G_trial.norm() < g_norm;
      if (accepted) orbit.newton_step_fractions.push_back(lambda);
    }
    if (!accepted) throw failure("stalled (no step along the Newton direction reduces the residual)");
    previous_norm = g_norm;
    U.swap(trial);
    G.swap(G_trial);
    r = G.lpNorm<Eigen::Infinity>();
    orbit.newton_residuals.push_back(r);
  }
  orbit.history = std::move(U);
  orbit.residual = r;
  if (at_orbit) *at_orbit = std::move(lin);
  return orbit;
}

// How the coarsest level of nested shooting is solved: sparse-LU Newton on the periodic problem
// (orbit_newton.hpp), shooting, or (automatic) shooting and, if it fails, sparse-LU Newton from
// the same guess. Why shooting first: from the same guess both take the same number of Newton
// steps (quadratic convergence to the same fixed point), but a shooting step costs one map
// evaluation and a few GMRES products, a sparse-LU step the assembly and factorisation of the
// d K x d K periodic Jacobian (measured at N = 250, impact k = 1: 3 steps in 0.1 ms against
// 1.3 ms). Why the fallback: all K states being unknowns gives Newton on the periodic problem a
// wider basin for strongly unstable orbits than shooting on P(U) - U, whose error is amplified by
// the whole map.
enum class CoarseOrbitMethod { newton, shooting, automatic };

struct NestedShootingOptions {
  OrbitByShootingOptions shooting;
  OrbitByNewtonOptions newton;  // coarsest level, sparse LU
  CoarseOrbitMethod coarse_method = CoarseOrbitMethod::automatic;
  long guess_periods = 100;  // maps simulated from the initial history for the coarsest guess
  int coarse_N = 64;         // the coarsest level (or N itself below 2 coarse_N): shooting_levels
  int refinement = 8;        // N_i / N_{i-1}
};

// The levels N_0 < ... < N_L = grid.N (header): N_{i-1} = the valid N nearest N_i / refinement,
// while that is >= coarse_N, then the first valid N >= coarse_N unless that exceeds half the last.
// One level (N itself) when N < 2 coarse_N.
std::vector<int> shooting_levels(const HistoryGrid& grid, int coarse_N, int refinement);

// Nested shooting for the map's grid (header), from the constant initial history y0 at the
// coarsest level. The returned orbit's `levels` lists every level; `maps` is guess_periods.
template <class Model, class Stepper>
PeriodicOrbit orbit_by_nested_shooting(const StroboscopicMap<Model, Stepper>& map, const Vec<Model::d>& y0,
                                       const NestedShootingOptions& opt,
                                       OrbitLinearisation<Model::d, delayed_rows<Model>>* at_orbit = nullptr) {
  using Map = StroboscopicMap<Model, Stepper>;
  if (opt.guess_periods < 0)
    throw BadInput("`orbit_guess_periods = " + std::to_string(opt.guess_periods) + "`: must be >= 0");
  const HistoryGrid& fine = map.grid();
  const std::vector<int> Ns = shooting_levels(fine, opt.coarse_N, opt.refinement);
  auto level_map = [&](int N) {
    return N == fine.N ? map : Map(map.stepper(), regrid(fine, N));
  };
  auto clock = [] { return std::chrono::steady_clock::now(); };
  auto since = [](auto t0) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };

  // Coarsest level: simulated guess, then Newton.
  auto t0 = clock();
  const Map coarse = level_map(Ns.front());
  const Eigen::VectorXd U = simulated_guess(coarse, coarse.constant_history(y0), opt.guess_periods,
                                            "orbit (N = " + std::to_string(Ns.front()) + ")");
  OrbitLinearisation<Model::d, delayed_rows<Model>> lin;
  PeriodicOrbit orbit;
  long linear_iterations = 0;
  std::vector<PeriodicOrbit::Level> levels;
  const bool last = Ns.size() == 1;
  auto by_newton = [&] {
    PeriodicOrbitProblem<Map> problem(coarse);
    orbit = orbit_by_newton(coarse, problem.sequence_from_history(U), opt.newton);
    coarse.apply(orbit.history, last && at_orbit ? &lin.maps : nullptr, &lin.states);
  };
  if (opt.coarse_method == CoarseOrbitMethod::newton) {
    by_newton();
  } else if (opt.coarse_method == CoarseOrbitMethod::shooting) {
    orbit = orbit_by_shooting(coarse, U, opt.shooting, &lin);
  } else {
    try {
      orbit = orbit_by_shooting(coarse, U, opt.shooting, &lin);
    } catch (const NumericalFailure& shooting_failure) {
      try {
        by_newton();
      } catch (const NumericalFailure& newton_failure) {
        throw NumericalFailure(std::string(newton_failure.what()) +
                               " (shooting from the same guess failed first: " + shooting_failure.what() + ")");
      }
    }
  }
  linear_iterations += orbit.linear_iterations;
  levels.push_back(
      {Ns.front(), orbit.method, orbit.newton_iterations, orbit.linear_iterations, orbit.residual, since(t0)});

  // Finer levels: shooting from the coarser orbit prolonged.
  for (size_t i = 1; i < Ns.size(); ++i) {
    t0 = clock();
    const Map level = level_map(Ns[i]);
    Eigen::VectorXd sequence(static_cast<long>(Model::d) * static_cast<long>(lin.states.size() - 1));
    for (size_t l = 0; l + 1 < lin.states.size(); ++l)
      sequence.segment<Model::d>(Model::d * static_cast<long>(l)) = lin.states[l];
    const Eigen::VectorXd guess = prolong_periodic_sequence(sequence, Model::d, regrid(fine, Ns[i - 1]), level.grid());
    orbit = orbit_by_shooting(level, PeriodicOrbitProblem<Map>(level).history(guess), opt.shooting, &lin);
    linear_iterations += orbit.linear_iterations;
    levels.push_back(
        {Ns[i], orbit.method, orbit.newton_iterations, orbit.linear_iterations, orbit.residual, since(t0)});
  }
  orbit.maps = opt.guess_periods;
  orbit.linear_iterations = linear_iterations;
  orbit.levels = std::move(levels);
  if (at_orbit) *at_orbit = std::move(lin);
  return orbit;
}

}  // namespace delayspec
