#pragma once
// Periodic orbits of an autonomous DDE, their period T an unknown (issue 35, item 3).
//
// Time scaled to one period: y(s) = x(T s) solves
//
//   y'(s) = T f(y(s), y(s - tau_1 / T), ..., y(s - tau_n / T)),   y(s + 1) = y(s),
//
// a DDE of period 1 whose delays tau_i / T move with T (TimeScaled). It is discretised as every
// periodic problem (orbit_newton.hpp: the sequence x = (u_0, ..., u_{K-1}), F_l = u_{l+1} -
// S_l(u_l, taps)) on a grid of exactly K steps per period, K = round(N T_guess / tau_max) fixed
// for the whole solve (make_grid_with_steps), each delay tapped where tau_i K / T falls: the
// fractional-delay taps of the forced case. Unknowns (x, T), equations F(x, T) = 0 and one phase
// condition, since every time shift of an orbit is an orbit too:
//
//   integral phase condition  sum_l <u_l - r_l, r'_l> = 0,
//
// r the reference sequence (Newton's guess) and r'_l = (r_{l+1} - r_{l-1}) / 2 its derivative in
// s (periodic central differences; the factor 1 / h drops out). It picks, among the orbit's time
// shifts, the one closest to the reference in L2 over the whole period; unlike a Poincare section
// through one point it needs no choice of component or level and stays well conditioned where
// the reference moves slowly at some point (as AUTO and DDE-BIFTOOL's collocation use it). It is
// linear in x: after Newton's first step it holds to rounding.
//
// Newton on the bordered system [F_x F_T; r'^T 0] (one sparse LU per iteration, UMFPACK), F_T by
// central differences, (F(x, T + d) - F(x, T - d)) / 2d with d = eps^(1/3) T (the error ~eps^(2/3)
// of the Jacobian's last column slows Newton, never moves its solution), with the line search of
// orbit_by_newton (full step unless |(F, g)|_2 grows; then halved). Newton finds unstable orbits
// as well as stable ones; its guess is one period of the map simulated from the model's constant
// history for guess_periods periods of T_guess.
//
// The orbit's monodromy (its multipliers) is that of the scaled map over one period
// (autonomous_orbit_map); the multiplier 1 of the time shift (the trivial multiplier) is exact for
// the exact orbit, so its distance from 1 is an accuracy check of the discretisation.
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "delayspec/detail/sparse_lu.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/grid.hpp"
#include "delayspec/memory_budget.hpp"
#include "delayspec/model.hpp"
#include "delayspec/orbit_newton.hpp"
#include "delayspec/step_options.hpp"
#include "delayspec/stepper.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec {

// The autonomous model Model on the time scale s = t / T: period 1, delays tau_i / T, field T f.
template <class Model>
struct TimeScaled {
  static_assert(AutonomousModel<Model>, "an orbit of unknown period needs an autonomous model (model.hpp)");
  static constexpr int d = Model::d;
  static constexpr int delay_count = delay_count_of<Model>();
  static constexpr bool has_switching = false;
  static constexpr bool affine_in_state = Model::affine_in_state;
  static constexpr bool is_linear = Model::is_linear;
  using Delayed = DelayedVec<Model>;

  Model model;
  double T = 1;

  double period() const { return 1; }
  std::array<double, delay_count> delays() const {
    const std::vector<double> taus = delays_of(model);
    std::array<double, delay_count> out{};
    for (int i = 0; i < delay_count; ++i) out[static_cast<size_t>(i)] = taus[static_cast<size_t>(i)] / T;
    return out;
  }
  double tau() const { return model.tau() / T; }
  Vec<d> f(int j, double, const Vec<d>& y, const Delayed& w) const { return T * model.f(j, 0.0, y, w); }
  Mat<d> A(int j, double, const Vec<d>& y, const Delayed& w) const { return T * model.A(j, 0.0, y, w); }
  DelayedMat<Model> B(int j, double, const Vec<d>& y, const Delayed& w) const { return T * model.B(j, 0.0, y, w); }
  Vec<d> initial_state() const { return model.initial_state(); }
};

// How the orbit is solved for: sparse-LU Newton on all K states and T (find_autonomous_orbit), or
// nested Newton-Krylov shooting on (U, T) from a sparse-LU coarse level (autonomous_shooting.hpp:
// for large N, where the LU fills in).
enum class AutonomousOrbitMethod { newton, shooting };
inline std::string to_string(AutonomousOrbitMethod method) {
  return method == AutonomousOrbitMethod::newton ? "newton" : "shooting";
}

struct AutonomousOrbitOptions {
  double period_guess = 0;  // T's starting value, > 0
  int N = 100;              // steps per the longest delay at T_guess: K = round(N T_guess / tau_max)
  int guess_periods = 10;   // periods of T_guess simulated from the constant history before Newton
  OrbitByNewtonOptions newton{1e-12, 30};  // tolerance and iterations, for shooting's too
  StepOptions step;
  AutonomousOrbitMethod method = AutonomousOrbitMethod::newton;
  int coarse_N = 64;  // shooting: the coarsest level's N, solved by sparse-LU Newton
};

struct AutonomousOrbit {
  AutonomousOrbitMethod method = AutonomousOrbitMethod::newton;  // of the finest level
  double period = 0;
  HistoryGrid grid;          // of the scaled problem: period 1, K steps
  Eigen::VectorXd sequence;  // u_0 .. u_{K-1}: the orbit at t = l T / K
  Eigen::VectorXd history;   // the history at s = 0: the fixed point of the scaled map
  double residual = 0;       // |F|_inf at the solution
  int newton_iterations = 0;             // all levels' (shooting)
  std::vector<double> newton_residuals;  // |(F, g)|_inf of each iterate, the guess first (the finest level's)
  std::vector<double> periods;           // T of each iterate, the guess first
};

// The index of the trivial multiplier among `mu` (the time shift's: the one nearest 1); 0 when empty.
inline size_t trivial_multiplier_index(const std::vector<std::complex<double>>& mu) {
  size_t trivial = 0;
  for (size_t i = 1; i < mu.size(); ++i)
    if (std::abs(mu[i] - 1.0) < std::abs(mu[trivial] - 1.0)) trivial = i;
  return trivial;
}

namespace detail {

// The scaled map at T on the K-step grid, its history M + 1 slots (M = 0: what T needs; more:
// slots beyond the longest tap, autonomous_shooting.hpp). BadInput when T needs more than M.
template <class Model>
StroboscopicMap<TimeScaled<Model>> scaled_map(const Model& model, double T, int K, const StepOptions& step,
                                              int M = 0) {
  const TimeScaled<Model> scaled{model, T};
  HistoryGrid g = make_grid_with_steps(delays_of(scaled), 1.0, K);
  if (M > 0) {
    if (g.M > M)
      throw BadInput("the period " + format_number(T) + " needs " + std::to_string(g.M + 1) + " history slots, " +
                     std::to_string(M + 1) + " laid");
    g.M = M;
  }
  return StroboscopicMap<TimeScaled<Model>>(TrapezoidStepper<TimeScaled<Model>>(scaled, step), g);
}


// Newton's guess: one period of the map at T after guess_periods - 1 simulated from the constant
// history.
template <class Model>
Eigen::VectorXd simulated_guess(const Model& model, double T, int K, const AutonomousOrbitOptions& o) {
  using Map = StroboscopicMap<TimeScaled<Model>>;
  const Map map = scaled_map(model, T, K, o.step);
  Eigen::VectorXd U = map.constant_history(model.initial_state());
  for (int i = 1; i < o.guess_periods; ++i) U = map.apply(U);
  const Eigen::VectorXd x = PeriodicOrbitProblem<Map>(map).sequence_from_history(U);
  if (!x.allFinite()) throw NumericalFailure("autonomous orbit: the simulated guess is not finite");
  return x;
}

// The phase condition's row: the reference's derivative in s, periodic central differences.
template <int D>
Eigen::VectorXd phase_row(const Eigen::VectorXd& reference, int K) {
  Eigen::VectorXd row(reference.size());
  for (long l = 0; l < K; ++l)
    row.segment<D>(D * l) =
        0.5 * (reference.segment<D>(D * ((l + 1) % K)) - reference.segment<D>(D * ((l + K - 1) % K)));
  return row;
}

// max_i (max_l u_l[i] - min_l u_l[i]): 0 for an equilibrium.
template <int D>
double amplitude(const Eigen::VectorXd& x, int K) {
  double out = 0;
  for (int i = 0; i < D; ++i) {
    const auto component =
        Eigen::Map<const Eigen::VectorXd, 0, Eigen::InnerStride<>>(x.data() + i, K, Eigen::InnerStride<>(D));
    out = std::max(out, component.maxCoeff() - component.minCoeff());
  }
  return out;
}

// Newton on (x, T) (header comment): F, the phase condition g, the bordered step, the line search.
template <class Model>
class PeriodNewton {
 public:
  using Map = StroboscopicMap<TimeScaled<Model>>;
  PeriodNewton(const Model& model, const AutonomousOrbitOptions& o, int K, const Eigen::VectorXd& reference)
      : model_(model), o_(o), K_(K), row_(phase_row<Model::d>(reference, K)), target_(row_.dot(reference)) {}

  // F(x, T), and F_x when asked; false where the model cannot be stepped (a delay shorter than
  // one step at this period, a step that fails, a value that is not finite).
  bool residual(const Eigen::VectorXd& x, double T, Eigen::SparseMatrix<double>* Fx, Eigen::VectorXd& F) const {
    try {
      const Map map = scaled_map(model_, T, K_, o_.step);
      F = PeriodicOrbitProblem<Map>(map).residual(x, Fx);
      return F.allFinite();
    } catch (const BadInput&) {
      return false;
    } catch (const NumericalFailure&) {
      return false;
    }
  }
  double phase(const Eigen::VectorXd& x) const { return row_.dot(x) - target_; }
  // |F|_inf <= tolerance (1 + |x|_inf), and g (linear) at its rounding level.
  bool converged(const Eigen::VectorXd& x, const Eigen::VectorXd& F, double g) const {
    const double g_scale = row_.cwiseAbs().dot(x.cwiseAbs()) + std::abs(target_);
    return F.lpNorm<Eigen::Infinity>() <= o_.newton.tolerance * (1 + x.lpNorm<Eigen::Infinity>()) &&
           std::abs(g) <= 1e-12 * (1 + g_scale);
  }
  // The Newton step (dx, dT) of [F_x F_T; row 0] = -(F, g), F_T by central differences; false
  // and why when F_T cannot be formed or the bordered matrix is singular.
  bool direction(const Eigen::VectorXd& x, double T, const Eigen::VectorXd& F, const Eigen::SparseMatrix<double>& Fx,
                 double g, Eigen::VectorXd& step, std::string& why) const {
    const double delta = std::cbrt(std::numeric_limits<double>::epsilon()) * T;
    Eigen::VectorXd up, down;
    if (!residual(x, T + delta, nullptr, up) || !residual(x, T - delta, nullptr, down)) {
      why = "the period's derivative could not be formed";
      return false;
    }
    const Eigen::VectorXd FT = (up - down) / ((T + delta) - (T - delta));
    Eigen::VectorXd rhs(x.size() + 1);
    rhs << -F, -g;
    try {
      step = SparseLU(bordered_matrix(Fx, FT, row_, 0.0)).solve(rhs);
    } catch (const NumericalFailure& e) {
      why = std::string("the bordered Jacobian cannot be factored (") + e.what() + ")";
      return false;
    }
    return true;
  }
  // The full step unless |(F, g)|_2 grows; then halved, at most 30 times. Updates x, T, F, Fx;
  // false when no fraction reduces the residual.
  bool line_search(const Eigen::VectorXd& step, Eigen::VectorXd& x, double& T, Eigen::VectorXd& F,
                   Eigen::SparseMatrix<double>& Fx) const {
    const long n = x.size();
    const double norm = std::hypot(F.norm(), phase(x));
    double lambda = 1;
    for (int halvings = 0; halvings <= 30; ++halvings, lambda *= 0.5) {
      const Eigen::VectorXd x_trial = x + lambda * step.head(n);
      const double T_trial = T + lambda * step[n];
      Eigen::SparseMatrix<double> Fx_trial;
      Eigen::VectorXd F_trial;
      if (!(T_trial > 0) || !residual(x_trial, T_trial, &Fx_trial, F_trial)) continue;
      if (std::hypot(F_trial.norm(), phase(x_trial)) < norm) {
        x = x_trial, T = T_trial, F = std::move(F_trial), Fx = std::move(Fx_trial);
        return true;
      }
    }
    return false;
  }

 private:
  const Model& model_;
  const AutonomousOrbitOptions& o_;
  int K_;
  Eigen::VectorXd row_;
  double target_;
};

}  // namespace detail

// The map over one period of a found orbit (its monodromy at orbit.history gives the multipliers).
template <class Model>
StroboscopicMap<TimeScaled<Model>> autonomous_orbit_map(const Model& model, const AutonomousOrbit& orbit,
                                                        const StepOptions& step = {}) {
  return detail::scaled_map(model, orbit.period, orbit.grid.K, step);
}

// K = round(N T_guess / tau_max), the steps per period of the options' N (header). BadInput:
// period_guess <= 0, N < 1, more than 2.5e8 steps.
template <class Model>
int autonomous_steps_per_period(const Model& model, const AutonomousOrbitOptions& o) {
  if (!(o.period_guess > 0) || !std::isfinite(o.period_guess))
    throw BadInput("`period_guess = " + format_number(o.period_guess) + "`: must be > 0");
  if (o.N < 1) throw BadInput("`N = " + std::to_string(o.N) + "`: must be >= 1");
  const std::vector<double> taus = delays_of(model);
  const double tau_max = *std::max_element(taus.begin(), taus.end());
  const double steps = std::max(1.0, std::round(o.N * o.period_guess / tau_max));
  if (steps > 2.5e8) throw BadInput("`N = " + std::to_string(o.N) + "`: too many steps per period");
  return static_cast<int>(steps);
}

// find_autonomous_orbit on a grid of K steps per period.
template <class Model>
AutonomousOrbit find_autonomous_orbit_with_steps(const Model& model, const AutonomousOrbitOptions& o, int K) {
  using Map = StroboscopicMap<TimeScaled<Model>>;
  constexpr int D = Model::d;
  // Sizes before allocation (memory_budget.hpp): the sparse LU of the K D unknowns fills the band
  // of the longest delay, M = K tau_max / T steps wide, so its factors hold at least K D x D M
  // doubles (measured on the Pyragas orbit, D = 2, M = 200: 212 MB resident at K = 20000, where
  // this bound says 128 MB). period_guess = 1e6 there asked for 190 GB and was killed by the kernel.
  {
    const std::vector<double> taus = delays_of(model);
    const double band = static_cast<double>(K) * *std::max_element(taus.begin(), taus.end()) / o.period_guess;
    require_memory(8.0 * K * D * D * std::max(1.0, band),
                   "`period_guess = " + format_number(o.period_guess) + "` (" + std::to_string(K) +
                       " steps per period at N = " + std::to_string(o.N) + ")",
                   "the sparse LU of the orbit's " + std::to_string(static_cast<long>(K) * D) +
                       " unknowns, its factors filling the band of the longest delay");
  }
  AutonomousOrbit out;
  double T = o.period_guess;
  Eigen::VectorXd x = detail::simulated_guess(model, T, K, o);
  const detail::PeriodNewton<Model> newton(model, o, K, x);
  auto failure = [&](const std::string& why, double r) {
    return NumericalFailure("autonomous orbit: " + why + " after " + std::to_string(out.newton_iterations) +
                            " Newton iterations from period_guess = " + format_number(o.period_guess) +
                            " (period reached " + format_number(T) + ", residual |F|_inf = " + format_number(r) +
                            "): no periodic orbit near the guess");
  };
  Eigen::SparseMatrix<double> Fx;
  Eigen::VectorXd F;
  if (!newton.residual(x, T, &Fx, F)) throw failure("the guess cannot be stepped", INFINITY);
  for (;;) {
    const double g = newton.phase(x), r = std::max(F.lpNorm<Eigen::Infinity>(), std::abs(g));
    out.newton_residuals.push_back(r);
    out.periods.push_back(T);
    if (newton.converged(x, F, g)) break;
    if (out.newton_iterations >= o.newton.max_iterations) throw failure("Newton did not converge", r);
    Eigen::VectorXd step;
    std::string why;
    if (!newton.direction(x, T, F, Fx, g, step, why)) throw failure(why, r);
    ++out.newton_iterations;
    if (!newton.line_search(step, x, T, F, Fx))
      throw failure("Newton stalled (no step along its direction reduces the residual)", r);
  }
  // An equilibrium solves F = 0 with any T: not an orbit.
  const double amplitude = detail::amplitude<D>(x, K);
  if (!(amplitude > 1e-6 * (1 + x.lpNorm<Eigen::Infinity>())))
    throw failure("Newton converged to an equilibrium (amplitude " + format_number(amplitude) + ")",
                  F.lpNorm<Eigen::Infinity>());
  const Map map = detail::scaled_map(model, T, K, o.step);
  const PeriodicOrbitProblem<Map> problem(map);
  out.period = T;
  out.grid = map.grid();
  out.sequence = x;
  out.history = problem.history(x);
  out.residual = F.lpNorm<Eigen::Infinity>();
  return out;
}

// The orbit near the simulated guess (header comment). BadInput: period_guess <= 0, N < 1, a
// grid whose delay is shorter than one step; NumericalFailure naming the residual and the period
// reached when Newton does not converge (a guess far from any orbit), or when the bordered matrix
// is singular (an equilibrium: no isolated orbit there).
template <class Model>
AutonomousOrbit find_autonomous_orbit(const Model& model, const AutonomousOrbitOptions& o) {
  return find_autonomous_orbit_with_steps(model, o, autonomous_steps_per_period(model, o));
}

}  // namespace delayspec
