#pragma once
// The discrete problem of a branch of orbits of unknown period (hopf_branch.hpp) at one parameter
// value: what the branch tracer (continuation_branch.hpp) and the locator ask of it. Part of
// hopf_branch.hpp's implementation, included by it; not an interface.
//
// Unknowns X = (x, T, p): the K states of the orbit on its own time scale (autonomous_orbit.hpp,
// K fixed along the branch), the period and the parameter. The tracer's x is (x, T); the
// problem G(x, T, p) = 0 it corrects is
//
//   F(x, T, p) = 0                      the scaled periodic problem (autonomous_orbit.hpp)
//   sum_l <u_l - r_l, r'_l> = 0         the integral phase condition against the corrector's
//                                       starting point r (the predictor: it moves with the branch)
//
// so G_x is [F_x F_T; r'^T 0] (F_T by central differences, as PeriodNewton) and G_p = (F_p, 0).
// The weighted inner product is the forced branch's, x.y / K + p q, with T counted among the
// states (weight 1 / K): the arclength follows the orbit and the parameter, T follows them.
//
// A point's multipliers: those of the scaled map's monodromy over one period, nev + 1 computed
// and the trivial one (the multiplier nearest 1: the time shift, 1 to rounding, autonomous.md)
// left out, so the detection counts and test functions of continuation.hpp see only the others.
#include <cmath>
#include <complex>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "delayspec/autonomous_orbit.hpp"
#include "delayspec/continuation.hpp"
#include "delayspec/detail/branch_corrector.hpp"
#include "delayspec/detail/condensed_bordered.hpp"

namespace delayspec::continuation_detail {

template <class Model, class ModelAt>
class AutonomousBranch final : public BranchProblem {
 public:
  static constexpr int D = Model::d;
  using Map = StroboscopicMap<TimeScaled<Model>>;
  using State = BranchState;  // x = (u_0, ..., u_{K-1}, T)

  AutonomousBranch(const ModelAt& model_at, int K, const ContinuationOptions& o)
      : BranchProblem(1.0 / K, o.newton.max_iterations), model_at_(model_at), o_(o), K_(K), range_(std::abs(o.to - o.from)) {}

  bool has_switching() const override { return false; }  // autonomous models do not switch (model.hpp)
  long unknowns() const override { return static_cast<long>(D) * K_ + 1; }

  // Newton from (x, T, p) on G = 0 and row_x . (x, T) + row_p p = target, the phase condition's
  // reference the starting point.
  std::optional<State> correct(Eigen::VectorXd x, double p, const Eigen::VectorXd& row_x, double row_p, double target,
                               int max_iterations, std::string& why, double& seconds) const override {
    const long n = unknowns() - 1;
    const Eigen::VectorXd phase = detail::phase_row<D>(x.head(n), K_);
    const double phase_target = phase.dot(x.head(n));
    auto linearise = [&](const Eigen::VectorXd& xT, double q,
                         std::string& reason) -> std::unique_ptr<BorderedLinearisation> {
      return linearisation_or_reason(xT, q, phase, phase_target, row_x, row_p, o_.solver, reason);
    };
    return bordered_corrector(linearise, std::move(x), p, row_x, row_p, target, max_iterations, o_.newton.tolerance,
                              weight_, CorrectorForcing{o_.forcing_max}, why, seconds, work_);
  }

  // The multipliers but the trivial one, the period and the extremes of the orbit at the point.
  ContinuationPoint evaluate(const State& s, double& krylov_seconds) const override {
    const long n = unknowns() - 1;
    ContinuationPoint point;
    point.parameter = s.p;
    point.period = s.x[n];
    point.newton_iterations = s.iterations;
    point.residual = s.residual;
    point.tangent_p = s.tp;
    const Map map = map_at(s.p, point.period);
    const Eigen::VectorXd U = PeriodicOrbitProblem<Map>(map).history(s.x.head(n));
    FloquetOptions floquet = o_.floquet;
    floquet.nev += 1;
    std::vector<std::complex<double>> mu = leading_multipliers(map.monodromy(U), floquet, krylov_seconds);
    const size_t trivial = trivial_multiplier_index(mu);
    if (!mu.empty()) point.trivial_multiplier = mu[trivial], mu.erase(mu.begin() + static_cast<long>(trivial));
    point.multipliers = std::move(mu);
    for (const auto& m : point.multipliers) point.unstable += std::abs(m) > 1;
    point.measures = state_extremes<D>(s.x.head(n), K_);
    return point;
  }

 private:
  Map map_at(double p, double T) const { return detail::scaled_map(model_at_(p), T, K_, o_.step_options); }
  Eigen::VectorXd residual(const Model& model, const Eigen::VectorXd& x, double T,
                           Eigen::SparseMatrix<double>* Fx) const {
    return PeriodicOrbitProblem<Map>(detail::scaled_map(model, T, K_, o_.step_options)).residual(x, Fx);
  }

  // G and its bordered matrix at (x, T, p) (header comment) for `solver` (ContinuationSolver):
  // G_x = [F_x F_T; phase 0] and G_p = (F_p, 0) assembled for the sparse LU, or for GMRES the step
  // maps and the borders of condensed_bordered.hpp, two here: columns (F_T, F_p), rows (phase,
  // row_x's state part), corner [0 0; row_x's T entry, row_p]. nullptr and the reason: a period <=
  // 0, a residual the stepper cannot compute, a parameter or period outside the model's domain (a
  // delay shorter than one step).
  std::unique_ptr<BorderedLinearisation> linearisation_or_reason(const Eigen::VectorXd& xT, double p,
                                                                 const Eigen::VectorXd& phase, double phase_target,
                                                                 const Eigen::VectorXd& row_x, double row_p,
                                                                 ContinuationSolver solver, std::string& why) const {
    const long n = unknowns() - 1;
    const Eigen::VectorXd x = xT.head(n);
    const double T = xT[n];
    if (!(T > 0) || !std::isfinite(T)) {
      why = "the period reached " + format_number(T) + " at parameter " + format_number(p);
      return nullptr;
    }
    try {
      const Model model = model_at_(p);  // once for F and F_T
      const Map map = detail::scaled_map(model, T, K_, o_.step_options);
      const bool lu = solver == ContinuationSolver::lu;
      Eigen::SparseMatrix<double> Fx;
      std::vector<StepMap<D, Map::DW>> maps;
      const Eigen::VectorXd F = PeriodicOrbitProblem<Map>(map).residual(x, lu ? &Fx : nullptr, lu ? nullptr : &maps);
      const double delta = std::cbrt(std::numeric_limits<double>::epsilon()) * T;
      const Eigen::VectorXd FT = (residual(model, x, T + delta, nullptr) - residual(model, x, T - delta, nullptr)) /
                                 ((T + delta) - (T - delta));
      const Eigen::VectorXd Fp =
          parameter_derivative([&](double q) { return residual(model_at_(q), x, T, nullptr); }, p, F, range_);
      Eigen::VectorXd G(n + 1);
      G << F, phase.dot(x) - phase_target;
      if (lu) {
        Eigen::VectorXd Gp = Eigen::VectorXd::Zero(n + 1);
        Gp.head(n) = Fp;
        return lu_linearisation(std::move(G), bordered_matrix(Fx, FT, phase, 0.0), std::move(Gp), row_x, row_p, p);
      }
      Borders borders;
      borders.columns.resize(n, 2);
      borders.columns << FT, Fp;
      borders.rows.resize(2, n);
      borders.rows << phase.transpose(), row_x.head(n).transpose();
      borders.corner = (Eigen::Matrix2d() << 0, 0, row_x[n], row_p).finished();
      auto krylov = std::make_unique<CondensedBordered<D, Map::DW>>(
          std::move(G), map.grid(), std::move(maps), std::move(borders), p,
          GmresLimits{o_.gmres_restart, o_.gmres_max_iterations});
      if (solver != ContinuationSolver::automatic) return krylov;
      return std::make_unique<FallBackToLu>(std::move(krylov), [this, xT, p, phase, phase_target, &row_x, row_p] {
        std::string ignored;  // the same iterate was just evaluated
        return linearisation_or_reason(xT, p, phase, phase_target, row_x, row_p, ContinuationSolver::lu, ignored);
      });
    } catch (const NumericalFailure& e) {
      why = std::string("residual not computable at ") + format_number(p) + " (" + e.what() + ")";
    } catch (const BadInput& e) {
      why = std::string("the model rejects parameter ") + format_number(p) + " with period " + format_number(T) +
            " (" + e.what() + ")";
    }
    return nullptr;
  }

  const ModelAt& model_at_;
  ContinuationOptions o_;
  int K_;
  double range_;
};

}  // namespace delayspec::continuation_detail
