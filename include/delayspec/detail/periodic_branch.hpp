#pragma once
// The discrete periodic problem of continuation.hpp at one parameter value, and what the branch
// tracer (continuation_branch.hpp) and the bifurcation locator (bifurcation_locator.hpp) ask of
// it: the bordered Newton corrector, F_x and F_p, the multipliers and the measures of a point.
// Part of continuation.hpp's implementation (its header states the mathematics), included by
// it; not an interface.
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "delayspec/continuation.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/grid.hpp"
#include "delayspec/model_grid.hpp"
#include "delayspec/orbit_newton.hpp"
#include "delayspec/detail/branch_corrector.hpp"
#include "delayspec/detail/condensed_bordered.hpp"
#include "delayspec/detail/contact_peaks.hpp"
#include "delayspec/detail/cubic_hermite.hpp"
#include "delayspec/stepper.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec::continuation_detail {

// The continued key changed the size of the discrete problem (e.g. a period that changes K): bad
// input, not a point outside the model's domain (which ends the branch).
class ProblemSizeChanged : public BadInput {
 public:
  using BadInput::BadInput;
};

using detail::contact_peaks;
using detail::ContactPeaks;     // (contact_peaks.hpp)
using detail::hermite_maximum;  // (cubic_hermite.hpp)

// The problem F(x, p) = 0 of one model factory and one discretisation (the options' N,
// periods_per_map, step options), with the weighted inner product of continuation.hpp.
template <class Model, class ModelAt>
class PeriodicBranch final : public BranchProblem {
 public:
  static constexpr int D = Model::d;
  using V = Vec<D>;
  using Map = StroboscopicMap<Model>;

  using State = BranchState;  // branch_corrector.hpp

  // `o` with its defaults filled in (the tracer's checked options): the corrector reads newton from it.
  PeriodicBranch(const ModelAt& model_at, const ContinuationOptions& o)
      : BranchProblem(1, o.newton.max_iterations), model_at_(model_at), o_(o) {
    const HistoryGrid g = grid_at(o.from);
    K_ = g.K;
    M_ = g.M;
    piece_steps_ = g.piece_steps;
    weight_ = 1.0 / static_cast<double>(K_);
    range_ = std::abs(o.to - o.from);
  }

  bool has_switching() const override { return Model::has_switching; }
  long unknowns() const override { return static_cast<long>(D) * K_; }

  Map map_at(double p) const {
    const Model model = model_at_(p);
    const HistoryGrid g = grid_at_model(model, p);
    return Map(TrapezoidStepper<Model>(model, o_.step_options), g);
  }

  // Newton from (x, p) on F = 0 and row_x . x + row_p p = target (bordered_corrector), each
  // bordered system solved as the options' solver says (ContinuationSolver).
  std::optional<State> correct(Eigen::VectorXd x, double p, const Eigen::VectorXd& row_x, double row_p, double target,
                               int max_iterations, std::string& why, double& seconds) const override {
    auto linearise = [&](const Eigen::VectorXd& x, double p,
                         std::string& why) -> std::unique_ptr<BorderedLinearisation> {
      try {
        return uses_krylov() ? krylov_linearisation(x, p, row_x, row_p) : lu_linearisation_at(x, p, row_x, row_p);
      } catch (const NumericalFailure& e) {
        why = std::string("residual not computable at ") + format_number(p) + " (" + e.what() + ")";
      } catch (const ProblemSizeChanged&) {
        throw;
      } catch (const BadInput& e) {  // p (or p +- delta) outside the model's domain
        why = std::string("the model rejects parameter ") + format_number(p) + " (" + e.what() + ")";
      }
      return nullptr;
    };
    return bordered_corrector(linearise, std::move(x), p, row_x, row_p, target, max_iterations, o_.newton.tolerance,
                              weight_, CorrectorForcing{o_.forcing_max}, why, seconds, work_);
  }

  // Multipliers and measures of the orbit x at p.
  ContinuationPoint evaluate(const State& s, double& krylov_seconds) const override {
    ContinuationPoint point;
    point.parameter = s.p;
    point.newton_iterations = s.iterations;
    point.residual = s.residual;
    point.tangent_p = s.tp;
    const Map map = map_at(s.p);
    PeriodicOrbitProblem<Map> problem(map);
    point.multipliers = leading_multipliers(map.monodromy(problem.history(s.x)), o_.floquet, krylov_seconds);
    for (const auto& mu : point.multipliers) point.unstable += std::abs(mu) > 1;
    point.measures = measures(map, s.x);
    return point;
  }

  // The orbit's extremes per component; for a switching model also max H between the nodes and
  // the contact time (OrbitMeasures).
  OrbitMeasures measures(const Map& map, const Eigen::VectorXd& x) const {
    OrbitMeasures m = state_extremes<D>(x, K_);
    if constexpr (Model::has_switching) {
      const Eigen::Map<const Eigen::Matrix<double, D, Eigen::Dynamic>> states(x.data(), D, K_);
      switching_measures(map, states, m);
    }
    return m;
  }

  const ContinuationOptions& options() const { return o_; }

 private:
  using States = Eigen::Map<const Eigen::Matrix<double, D, Eigen::Dynamic>>;

  bool uses_krylov() const { return o_.solver != ContinuationSolver::lu; }
  // F_p (parameter_derivative: central differences, one-sided at a bound of the key's range).
  Eigen::VectorXd F_p(const Eigen::VectorXd& x, double p, const Eigen::VectorXd& F) const {
    return parameter_derivative([&](double q) { return PeriodicOrbitProblem<Map>(map_at(q)).residual(x); }, p, F,
                                range_);
  }
  // The bordered system at (x, p) for the sparse LU: F, F_x, F_p assembled.
  std::unique_ptr<BorderedLinearisation> lu_linearisation_at(const Eigen::VectorXd& x, double p,
                                                             const Eigen::VectorXd& row_x, double row_p) const {
    Eigen::SparseMatrix<double> Fx;
    Eigen::VectorXd F = PeriodicOrbitProblem<Map>(map_at(p)).residual(x, &Fx);
    Eigen::VectorXd Fp = F_p(x, p, F);
    return lu_linearisation(std::move(F), std::move(Fx), std::move(Fp), row_x, row_p, p);
  }
  // The bordered system at (x, p) matrix-free: F, the step maps and F_p (condensed_bordered.hpp);
  // with continue_solver = auto a solve GMRES fails is done again by the sparse LU.
  std::unique_ptr<BorderedLinearisation> krylov_linearisation(const Eigen::VectorXd& x, double p,
                                                              const Eigen::VectorXd& row_x, double row_p) const {
    const Map map = map_at(p);
    std::vector<StepMap<D, delayed_rows<Model>>> maps;
    Eigen::VectorXd F = PeriodicOrbitProblem<Map>(map).residual(x, nullptr, &maps);
    Eigen::VectorXd Fp = F_p(x, p, F);
    const GmresLimits limits{o_.gmres_restart, o_.gmres_max_iterations};
    Borders borders{std::move(Fp), row_x.transpose(), Eigen::MatrixXd::Constant(1, 1, row_p)};
    auto krylov = std::make_unique<CondensedBordered<D, delayed_rows<Model>>>(std::move(F), map.grid(), std::move(maps),
                                                                             std::move(borders), p, limits);
    if (o_.solver != ContinuationSolver::automatic) return krylov;
    return std::make_unique<FallBackToLu>(
        std::move(krylov), [this, x, p, &row_x, row_p]() -> std::unique_ptr<BorderedLinearisation> {
          try {
            return lu_linearisation_at(x, p, row_x, row_p);
          } catch (const std::exception&) {  // the same iterate was just evaluated: not expected
            return nullptr;
          }
        });
  }

  // Switching models: over each step [t, t + h] of the orbit, max H from the cubic Hermite
  // interpolant of H(y(t)) with the slopes dH/dt = grad H . f at both nodes (H affine,
  // model.hpp), and the time in region 1 from the step's events (none with events off: the
  // node's region). The delayed states from HistoryGrid::delay_tap, the orbit repeated
  // periodically into the past: slot M + l of the history is u_{l mod K}.
  void switching_measures(const Map& map, const States& states, OrbitMeasures& m) const {
    const HistoryGrid& g = map.grid();
    const Model& model = map.stepper().model();
    const long M = g.M;
    auto u = [&](long l) { return V(states.col(((l % K_) + K_) % K_)); };
    auto slot = [&](long i) { return u(i - M); };
    m.max_H = -INFINITY;
    m.contact_time = 0;
    std::vector<double> node_H(K_), step_max_H(K_);  // the humps of H (contact_peaks.hpp)
    StepMap<D, delayed_rows<Model>> scratch;
    for (long l = 0; l < K_; ++l) {
      const auto [w0, w1, t, h] = g.template delay_taps<D, DelayedVec<Model>>(l, slot);
      const V a = u(l), b = u(l + 1);
      const int ja = region_of(model, a), jb = region_of(model, b);
      const V grad = model.grad_H(a);
      node_H[l] = model.H(a);
      step_max_H[l] = hermite_maximum(node_H[l], model.H(b), grad.dot(model.f(ja, t, a, w0)),
                                      grad.dot(model.f(jb, t + h, b, w1)), h);
      m.max_H = std::max(m.max_H, step_max_H[l]);
      StepEvents events;
      map.stepper().step(t, h, a, w0, w1, scratch, &events);
      int region = ja;
      double position = 0;
      for (int e = 0; e < events.count; ++e) {
        if (region == 1) m.contact_time += events.offset[e] - position;
        position = events.offset[e];
        region = events.new_region[e];
      }
      if (region == 1) m.contact_time += h - position;
    }
    const ContactPeaks peaks = contact_peaks(node_H, step_max_H);
    m.second_max_H = peaks.second_max;
    m.contact_regions = peaks.regions;
  }

  HistoryGrid grid_at(double p) const { return grid_at_model(model_at_(p), p); }
  HistoryGrid grid_at_model(const Model& model, double p) const {
    // Aligned with the model's time switches, the pieces keep the start's steps (piece_steps_),
    // so that the discrete problem moves smoothly with p (grid.hpp)
    const HistoryGrid g = make_grid(delays_of(model), model.period(), o_.N, o_.periods_per_map, {},
                                    grid_breaks(model, o_.step_options.grid, piece_steps_));
    if (K_ != 0 && (g.K != K_ || g.M != M_))
      throw ProblemSizeChanged("continuation: at parameter " + format_number(p) +
                               " the grid has K = " + std::to_string(g.K) + ", M = " + std::to_string(g.M) +
                               " (at the start K = " + std::to_string(K_) + ", M = " + std::to_string(M_) +
                               "): the continued key must not change the size of the discrete problem");
    return g;
  }

  const ModelAt& model_at_;
  ContinuationOptions o_;
  long K_ = 0, M_ = 0;
  std::vector<int> piece_steps_;  // the start's allocation on an aligned grid (grid_at_model)
  double range_ = 1;
};

}  // namespace delayspec::continuation_detail
