#pragma once
// Equilibria of an autonomous DDE and their rightmost characteristic roots (issue 35, item 1):
//
//   y' = f(y(t), y(t - tau_1), ..., y(t - tau_n)),   an equilibrium y*: f(y*, y*, ..., y*) = 0.
//
// Linearised at y*: y' = A y + sum_i B_i y(t - tau_i), A = df/dy, B_i = df/dw_i there. Its
// characteristic roots are the zeros of
//
//   c(lambda) = det Delta(lambda),   Delta(lambda) = lambda I - A - sum_i B_i exp(-lambda tau_i).
//
// Three stages:
//  1. y* by Newton on g(y) = f(y, y, ..., y), g' = A + sum_i B_i, from a guess.
//  2. The rightmost roots approximately, from the engine's matrix-free monodromy over the horizon
//     T = tau_max of the model's own map linearised at the constant history y* (a fixed point
//     of the map for an autonomous model: its step maps are those of the linearisation, so
//     no other stepper is compiled; Krylov as for orbits): a multiplier mu = exp(lambda T) gives
//     lambda = (log |mu| + i (arg mu + 2 pi k)) / T, and the branch k is the one where |c| / |c'|
//     (the Newton step's length) is least.
//  3. Each refined by Newton on c itself, lambda <- lambda - 1 / tr(Delta^{-1} Delta'),
//     Delta' = I + sum_i tau_i B_i exp(-lambda tau_i) (Jacobi's formula for c'/c), to
//     |step| <= tolerance (1 + |lambda|): the returned roots carry no discretisation error. How
//     far each moved is reported (it is the discretisation's error at N), and the residual
//     sigma_min(Delta(lambda)) / (|lambda| + |A| + sum |B_i|): lambda is an exact root of a
//     system whose coefficients are perturbed by that relative amount (2-norms).
//
// The model must be autonomous (model.hpp: f independent of t; evaluated at t = 0, region 1),
// which excludes switching; checked at compile time. Stages 1 and 3 work on the model's values at
// a constant history (ConstantHistory), the one form the branch of equilibria
// (equilibrium_branch.hpp) also takes; they are compiled once, in the library.
#include <algorithm>
#include <complex>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "delayspec/floquet.hpp"
#include "delayspec/model.hpp"
#include "delayspec/monodromy.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec {

struct EquilibriumOptions {
  int N = 100;                // steps per tau_max for stage 2 (the starting roots)
  int nroots = 6;             // rightmost roots returned
  double tolerance = 1e-12;   // Newton, relative: |step| <= tolerance (1 + |x|)
  int max_iterations = 50;    // Newton steps, each stage
  // The eigensolver of stage 2 (its nev is set here: nroots + 4, for the roots that refine to
  // one another).
  FloquetOptions eigensolver;
};

struct CharacteristicRoot {
  std::complex<double> value;        // refined on c(lambda)
  std::complex<double> discretised;  // from the monodromy at N (stage 2)
  double last_step = 0;              // |lambda_k+1 - lambda_k| of Newton's last step
  double residual = 0;               // sigma_min(Delta) / (|lambda| + |A| + sum |B_i|) (header comment)
  // A bound on |value - exact root|: Newton's last step (quadratic convergence: the error after
  // it is far below it), and never below rounding, 4 eps (1 + |lambda|).
  double error_bound = 0;
  int iterations = 0;
};

struct EquilibriumResult {
  Eigen::VectorXd state;                  // y*
  double residual = 0;                    // |f(y*, ..., y*)|_inf
  int newton_iterations = 0;
  std::vector<CharacteristicRoot> roots;  // rightmost first (largest real part)
  int unstable = 0;                       // roots with Re lambda > error_bound
  int critical = 0;                       // roots with |Re lambda| <= error_bound: no sign to tell
  std::string note;                       // when other than nroots roots come back: how many and why
  bool stable() const { return unstable == 0 && critical == 0; }
};

// A model's values on the constant history y (every delayed state = y): f, A and the B_i side
// by side (d x d n), and the delays.
struct ConstantHistory {
  Eigen::VectorXd f;
  Eigen::MatrixXd A, B;
  std::vector<double> taus;
  Eigen::MatrixXd jacobian() const;  // d f(y, ..., y) / dy = A + sum_i B_i
  // Delta(lambda) = lambda I - A - sum_i B_i exp(-lambda tau_i), and Delta'(lambda) when asked.
  Eigen::MatrixXcd delta(std::complex<double> lambda, Eigen::MatrixXcd* derivative = nullptr) const;
  // c / c' at lambda = 1 / tr(Delta^{-1} Delta') (Jacobi's formula): Newton's step on c.
  std::complex<double> newton_step(std::complex<double> lambda) const;
  // sigma_min(Delta(lambda)) / (|lambda| + |A| + sum_i |B_i|), 2-norms.
  double residual(std::complex<double> lambda) const;
  // The unit vector c with |Delta(lambda) c| least: the right singular vector of the smallest
  // singular value (at a root, Delta(lambda) c = 0: the critical eigenvector of a Hopf point),
  // its phase fixed by its entry of largest modulus being real and positive.
  Eigen::VectorXcd null_vector(std::complex<double> lambda) const;
};

template <class Model>
ConstantHistory constant_history(const Model& model, const Vec<Model::d>& y) {
  constexpr int D = Model::d, NT = delay_count_of<Model>();
  Vec<D * NT> w;
  for (int i = 0; i < NT; ++i) w.template segment<D>(i * D) = y;
  return {model.f(1, 0.0, y, w), model.A(1, 0.0, y, w), model.B(1, 0.0, y, w), delays_of(model)};
}

// Stage 1: Newton on f(y, ..., y) = 0 from y, `at(y)` the model's values there. Fills state,
// residual and newton_iterations of r. NumericalFailure: a singular Jacobian, no convergence.
void equilibrium_state(const std::function<ConstantHistory(const Eigen::VectorXd&)>& at, Eigen::VectorXd y,
                       const EquilibriumOptions& o, EquilibriumResult& r);

// Stage 3: Newton on c from lambda; NumericalFailure when it does not converge. `discretised`
// is where it started.
CharacteristicRoot refined_root(const ConstantHistory& at_equilibrium, std::complex<double> lambda,
                                const EquilibriumOptions& o);

// Stage 3 for the multipliers mu of the monodromy over T (stage 2): each one's root (the branch
// of log mu / T where Newton's step is shortest, then refined_root), two that refine to one root
// (within the sum of their error bounds) counted once, a complex root's conjugate added when
// missing, sorted rightmost first, the nroots first kept (and the partner of a pair the cut would
// split), unstable and critical counted; `note` says when other than nroots come back, and why.
void refine_multipliers(const ConstantHistory& at_equilibrium, const Multipliers& mu, double T,
                        const EquilibriumOptions& o, EquilibriumResult& r);

// Stages 1-3 above. BadInput: options out of range; NumericalFailure naming the residual when
// Newton for y* does not converge, or a root's refinement does not.
template <class Model>
EquilibriumResult find_equilibrium(const Model& model, const Vec<Model::d>& guess, const EquilibriumOptions& o = {}) {
  static_assert(AutonomousModel<Model>, "equilibria need an autonomous model (model.hpp: autonomous = true)");
  constexpr int D = Model::d;
  if (o.nroots < 1) throw BadInput("`nroots = " + std::to_string(o.nroots) + "`: must be >= 1");
  if (!(o.tolerance > 0)) throw BadInput("`equilibrium_tolerance`: must be > 0");
  EquilibriumResult r;
  equilibrium_state([&](const Eigen::VectorXd& y) { return constant_history(model, Vec<D>(y)); }, guess, o, r);

  // Stage 2: the multipliers of the model's map over T = tau_max at the constant history y*
  const Vec<D> y = r.state;
  const std::vector<double> taus = delays_of(model);
  const double T = *std::max_element(taus.begin(), taus.end());
  const StroboscopicMap<Model> map(TrapezoidStepper<Model>(model), make_grid(taus, T, o.N));
  std::vector<StepMap<D, delayed_rows<Model>>> steps;
  map.apply(map.constant_history(y), &steps);
  FloquetOptions fo = o.eigensolver;
  fo.nev = static_cast<int>(std::min<long>(o.nroots + 4, map.dimension() - 2));
  const Monodromy<D, delayed_rows<Model>> monodromy(map.grid(), std::move(steps));
  refine_multipliers(constant_history(model, y), floquet_multipliers(monodromy, fo).multipliers, T, o, r);
  return r;
}

}  // namespace delayspec
