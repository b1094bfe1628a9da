#pragma once
// Equilibria of an autonomous DDE and their rightmost characteristic roots (issue 35, item 1;
// engine part):
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
//     far each moved is reported (it is the discretisation's error at N).
//
// The model must be autonomous (f independent of t; evaluated at t = 0, region 1) and without
// switching; the caller checks (has_switching is refused at compile time).
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "delayspec/errors.hpp"
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
  bool stable() const { return unstable == 0 && critical == 0; }
};

namespace detail {

// Delta(lambda) = lambda I - A - sum_i B_i exp(-lambda tau_i) of the linearisation at y*.
template <int D, int NT>
struct CharacteristicMatrix {
  Mat<D> a;
  RectMat<D, D * NT> b;
  std::array<double, NT> taus;

  // Delta(lambda) and Delta'(lambda).
  using CMat = Eigen::Matrix<std::complex<double>, D, D>;
  void delta(std::complex<double> l, CMat& value, CMat& derivative) const {
    value = l * CMat::Identity() - a.template cast<std::complex<double>>();
    derivative = CMat::Identity();
    for (int i = 0; i < NT; ++i) {
      const std::complex<double> e = std::exp(-l * taus[i]);
      const CMat bi = b.template middleCols<D>(i * D).template cast<std::complex<double>>();
      value -= e * bi;
      derivative += taus[i] * e * bi;
    }
  }
  // The Newton step c / c' = 1 / tr(Delta^{-1} Delta') (infinite where Delta is singular: a root).
  std::complex<double> newton_step(std::complex<double> l) const {
    CMat value, derivative;
    delta(l, value, derivative);
    const Eigen::PartialPivLU<CMat> lu(value);
    const std::complex<double> trace = lu.solve(derivative).trace();
    return 1.0 / trace;
  }
  // sigma_min(Delta(lambda)) / (|lambda| + |A| + sum_i |B_i|), 2-norms.
  double residual(std::complex<double> l) const {
    CMat value, derivative;
    delta(l, value, derivative);
    double scale = std::abs(l) + singular_value(a, false);
    for (int i = 0; i < NT; ++i) scale += singular_value(Mat<D>(b.template middleCols<D>(i * D)), false);
    return singular_value(value, true) / scale;
  }
  // The smallest or largest singular value of a D x D matrix (1 x 1: its modulus, which also
  // spares GCC's false maybe-uninitialized warning on a 1 x 1 JacobiSVD).
  template <class M>
  static double singular_value(const M& m, bool smallest) {
    if constexpr (D == 1) {
      return std::abs(m(0, 0));
    } else {
      const auto values = Eigen::JacobiSVD<M>(m).singularValues();
      return smallest ? values(D - 1) : values(0);
    }
  }
};

// The n copies of y stacked: the delayed argument of f on a constant history.
template <int D, int NT>
Vec<D * NT> stacked(const Vec<D>& y) {
  Vec<D * NT> w;
  for (int i = 0; i < NT; ++i) w.template segment<D>(i * D) = y;
  return w;
}

// Stage 1: Newton on g(y) = f(y, y, ..., y), g' = A + sum_i B_i. Fills state, residual and
// newton_iterations of r.
template <class Model>
void equilibrium_state(const Model& model, Vec<Model::d> y, const EquilibriumOptions& o, EquilibriumResult& r) {
  constexpr int D = Model::d, NT = delay_count_of<Model>();
  for (;; ++r.newton_iterations) {
    const Vec<D> g = model.f(1, 0.0, y, stacked<D, NT>(y));
    r.residual = g.template lpNorm<Eigen::Infinity>();
    const RectMat<D, D * NT> b = model.B(1, 0.0, y, stacked<D, NT>(y));
    Mat<D> jacobian = model.A(1, 0.0, y, stacked<D, NT>(y));
    for (int i = 0; i < NT; ++i) jacobian += b.template middleCols<D>(i * D);
    const Eigen::FullPivLU<Mat<D>> lu(jacobian);
    if (!lu.isInvertible())
      throw NumericalFailure("equilibrium: the Jacobian A + sum B of f(y, ..., y) is singular at the iterate " +
                             std::to_string(r.newton_iterations) + " (|f|_inf = " + format_number(r.residual) +
                             "): no isolated equilibrium there");
    const Vec<D> step = lu.solve(g);
    if (!y.allFinite() || !step.allFinite() || r.newton_iterations >= o.max_iterations)
      throw NumericalFailure("equilibrium: Newton did not converge from the guess (|f(y, ..., y)|_inf = " +
                             format_number(r.residual) + " after " + std::to_string(r.newton_iterations) +
                             " iterations)");
    y -= step;
    if (step.template lpNorm<Eigen::Infinity>() <= o.tolerance * (1 + y.template lpNorm<Eigen::Infinity>())) {
      r.residual = model.f(1, 0.0, y, stacked<D, NT>(y)).template lpNorm<Eigen::Infinity>();
      ++r.newton_iterations;
      break;
    }
  }
  r.state = y;
}

// Stage 3 for one multiplier mu of the monodromy over T: the branch of log mu / T where the
// Newton step on c is shortest, then Newton on c.
template <int D, int NT>
CharacteristicRoot refined_root(const CharacteristicMatrix<D, NT>& lin, std::complex<double> mu, double T,
                                const EquilibriumOptions& o) {
  const double two_pi = 2 * std::numbers::pi;
  const int branches = o.N / 2 + 1;  // frequencies the grid resolves: |Im lambda| T / 2 pi < N / 2
  CharacteristicRoot root;
  double best = INFINITY;
  for (int k = -branches; k <= branches; ++k) {
    const std::complex<double> l(std::log(std::abs(mu)) / T, (std::arg(mu) + two_pi * k) / T);
    const double step = std::abs(lin.newton_step(l));
    if (step < best) best = step, root.discretised = l;
  }
  std::complex<double> l = root.discretised;
  for (root.iterations = 1;; ++root.iterations) {
    const std::complex<double> step = lin.newton_step(l);
    l -= step;
    root.last_step = std::abs(step);
    if (!std::isfinite(l.real()) || !std::isfinite(l.imag()) || root.iterations >= o.max_iterations)
      throw NumericalFailure("equilibrium: the characteristic root near " + format_number(root.discretised.real()) +
                             (root.discretised.imag() < 0 ? " - " : " + ") +
                             format_number(std::abs(root.discretised.imag())) +
                             "i did not converge on det(lambda I - A - sum B e^(-lambda tau)) (last step " +
                             format_number(root.last_step) + ")");
    if (root.last_step <= o.tolerance * (1 + std::abs(l))) break;
  }
  root.value = l;
  root.residual = lin.residual(l);
  root.error_bound = std::max(root.last_step, 4 * std::numeric_limits<double>::epsilon() * (1 + std::abs(l)));
  return root;
}

}  // namespace detail

// Stages 1-3 above. BadInput: options out of range; NumericalFailure naming the residual when
// Newton for y* does not converge, or a root's refinement does not.
template <class Model>
EquilibriumResult find_equilibrium(const Model& model, const Vec<Model::d>& guess, const EquilibriumOptions& o = {}) {
  static_assert(AutonomousModel<Model>, "equilibria need an autonomous model (model.hpp: autonomous = true)");
  constexpr int D = Model::d, NT = delay_count_of<Model>();
  if (o.nroots < 1) throw BadInput("`nroots = " + std::to_string(o.nroots) + "`: must be >= 1");
  if (!(o.tolerance > 0)) throw BadInput("`equilibrium_tolerance`: must be > 0");
  EquilibriumResult r;
  detail::equilibrium_state(model, guess, o, r);

  // Stage 2: the multipliers of the model's map over T = tau_max at the constant history y*
  const Vec<D> y = r.state;
  detail::CharacteristicMatrix<D, NT> lin;
  lin.a = model.A(1, 0.0, y, detail::stacked<D, NT>(y));
  lin.b = model.B(1, 0.0, y, detail::stacked<D, NT>(y));
  const std::vector<double> taus = delays_of(model);
  std::copy(taus.begin(), taus.end(), lin.taus.begin());
  const double T = *std::max_element(taus.begin(), taus.end());
  const StroboscopicMap<Model> map(TrapezoidStepper<Model>(model), make_grid(taus, T, o.N));
  std::vector<StepMap<D, delayed_rows<Model>>> steps;
  map.apply(map.constant_history(y), &steps);
  FloquetOptions fo = o.eigensolver;
  fo.nev = static_cast<int>(std::min<long>(o.nroots + 4, map.dimension() - 2));
  const Monodromy<D, delayed_rows<Model>> monodromy(map.grid(), std::move(steps));
  const Multipliers mu = floquet_multipliers(monodromy, fo).multipliers;

  // Stage 3, each multiplier; two that refine to one root count once
  for (const std::complex<double>& m : mu) {
    if (std::abs(m) == 0) continue;
    const CharacteristicRoot root = detail::refined_root(lin, m, T, o);
    const bool seen = std::any_of(r.roots.begin(), r.roots.end(), [&](const CharacteristicRoot& other) {
      return std::abs(other.value - root.value) <= 1e3 * o.tolerance * (1 + std::abs(root.value));
    });
    if (!seen) r.roots.push_back(root);
  }
  std::sort(r.roots.begin(), r.roots.end(), [](const CharacteristicRoot& p, const CharacteristicRoot& q) {
    return p.value.real() != q.value.real() ? p.value.real() > q.value.real() : p.value.imag() > q.value.imag();
  });
  if (static_cast<int>(r.roots.size()) > o.nroots) r.roots.resize(static_cast<size_t>(o.nroots));
  for (const CharacteristicRoot& c : r.roots) {
    if (c.value.real() > c.error_bound) ++r.unstable;
    else if (c.value.real() >= -c.error_bound) ++r.critical;
  }
  return r;
}

}  // namespace delayspec
