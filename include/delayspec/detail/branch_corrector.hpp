#pragma once
// What both branches of periodic orbits share (periodic_branch.hpp: a forced orbit, unknowns x;
// autonomous_branch.hpp: an orbit of unknown period, unknowns (x, T)): the corrected point with
// its tangent, the bordered Newton corrector, the parameter derivative by differences, the
// leading multipliers of a point, the orbit's extremes. Part of continuation.hpp's
// implementation (its header states the mathematics); not an interface.
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
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

// The linear algebra of Newton corrections: sparse LU factorisations, GMRES products (each one
// application of the linearised map).
struct CorrectorWork {
  long factorisations = 0;
  long products = 0;
};

// The discrete problem along a branch, as the tracer and the locator (continuation_branch.cpp)
// ask it: an abstract class, so that they are compiled once in the library and only the problem
// (PeriodicBranch, AutonomousBranch) per model: the same work at every corrected point (one
// sparse LU per Newton step, an eigensolve per point) dwarfs a virtual call.
class BranchProblem {
 public:
  using State = BranchState;
  virtual ~BranchProblem() = default;
  virtual bool has_switching() const = 0;  // grazing is watched (max H over the orbit)
  virtual long unknowns() const = 0;       // entries of x
  // Newton from (x, p) on the problem and row_x . x + row_p p = target (bordered_corrector).
  virtual std::optional<BranchState> correct(Eigen::VectorXd x, double p, const Eigen::VectorXd& row_x, double row_p,
                                             double target, int max_iterations, std::string& why,
                                             double& seconds) const = 0;
  // The multipliers, measures (and period) at a corrected point.
  virtual ContinuationPoint evaluate(const BranchState& s, double& krylov_seconds) const = 0;

  // The weighted inner product of continuation.hpp: x.y / K + p q.
  double dot(const Eigen::VectorXd& ax, double ap, const Eigen::VectorXd& bx, double bp) const {
    return weight_ * ax.dot(bx) + ap * bp;
  }
  // The linear algebra of every correction so far (factorisations, GMRES products).
  const CorrectorWork& work() const { return work_; }

  // The corrected point at arclength s from `base` along its tangent: the predictor
  // X_pred = X_base + s t_base, corrected on the hyperplane <t_base, X - X_pred>_w = 0.
  std::optional<BranchState> point_along(const BranchState& base, double s, std::string& reason,
                                         double& seconds) const {
    const Eigen::VectorXd pred_x = base.x + s * base.tx;
    const double pred_p = base.p + s * base.tp;
    const Eigen::VectorXd row_x = weight_ * base.tx;
    return correct(pred_x, pred_p, row_x, base.tp, row_x.dot(pred_x) + base.tp * pred_p, max_iterations_, reason,
                   seconds);
  }

 protected:
  // weight: 1 / K; max_iterations: the corrector's along the branch
  BranchProblem(double weight, int max_iterations) : weight_(weight), max_iterations_(max_iterations) {}
  BranchProblem(const BranchProblem&) = default;
  BranchProblem& operator=(const BranchProblem&) = default;
  double weight_ = 1;
  int max_iterations_ = 10;
  mutable CorrectorWork work_;  // one branch is traced by one thread
};

// Adds the time from construction to destruction to `seconds`.
struct ScopedSeconds {
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  double& seconds;
  explicit ScopedSeconds(double& s) : seconds(s) {}
  ~ScopedSeconds() { seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); }
};

// One Newton iterate of the bordered corrector: G at the iterate and its Newton matrix
//   [ G_x    G_p   ]
//   [ row_x  row_p ],
// ready to solve: factored whole by a sparse LU (lu_linearisation), or condensed onto the map's
// history and solved matrix-free by GMRES (detail/condensed_bordered.hpp). The work a solve
// needs (a factorisation) is done by its first solve, so that an iterate the corrector gives up
// on costs none.
class BorderedLinearisation {
 public:
  virtual ~BorderedLinearisation() = default;
  Eigen::VectorXd G;  // the residual at the iterate
  // z = (z_x, z_p) with the matrix times z = (rhs_x, rhs_p). forcing: the relative residual an
  // iterative solve may stop at (Newton's forcing term; a direct solve ignores it). nullopt and
  // why when the solve fails (a singular matrix, GMRES without convergence).
  virtual std::optional<Eigen::VectorXd> solve(const Eigen::VectorXd& rhs_x, double rhs_p, double forcing,
                                               std::string& why) = 0;
  // The work so far: sparse LU factorisations, GMRES products (each one application of the
  // linearised map).
  long factorisations = 0;
  long products = 0;
};

// The sparse-LU linearisation: G with its G_x, G_p and the border (UMFPACK, sparse_lu.hpp, on
// the (n + 1)-square bordered matrix). p: named when the matrix is singular. In the library.
std::unique_ptr<BorderedLinearisation> lu_linearisation(Eigen::VectorXd G, Eigen::SparseMatrix<double> G_x,
                                                        Eigen::VectorXd G_p, const Eigen::VectorXd& row_x,
                                                        double row_p, double p);

// An iterative linearisation with a direct one to fall back on: a solve the first fails (GMRES
// without convergence: a strongly unstable orbit, condensed_bordered.hpp) is done again by the
// second, made on first need (`make_fallback`: the same iterate, e.g. lu_linearisation; nullptr
// if it cannot be made, and the solve fails with the first's reason).
class FallBackToLu final : public BorderedLinearisation {
 public:
  FallBackToLu(std::unique_ptr<BorderedLinearisation> first,
               std::function<std::unique_ptr<BorderedLinearisation>()> make_fallback)
      : first_(std::move(first)), make_fallback_(std::move(make_fallback)) {
    G = first_->G;
  }
  std::optional<Eigen::VectorXd> solve(const Eigen::VectorXd& rhs_x, double rhs_p, double forcing,
                                       std::string& why) override {
    std::optional<Eigen::VectorXd> z;
    if (!fallback_) z = first_->solve(rhs_x, rhs_p, forcing, why);
    if (!z) {
      if (!fallback_) fallback_ = make_fallback_();
      if (fallback_) z = fallback_->solve(rhs_x, rhs_p, forcing, why);
    }
    factorisations = first_->factorisations + (fallback_ ? fallback_->factorisations : 0);
    products = first_->products + (fallback_ ? fallback_->products : 0);
    return z;
  }

 private:
  std::unique_ptr<BorderedLinearisation> first_, fallback_;
  std::function<std::unique_ptr<BorderedLinearisation>()> make_fallback_;
};

// Forcing terms of an iterative corrector (Eisenstat-Walker, as nested shooting: orbit_shooting.hpp).
struct CorrectorForcing {
  double forcing_max;      // eta_max: the options' (ContinuationOptions::forcing_max, where its default lives)
  double tangent = 1e-12;  // the tangent's relative residual (it orients the next predictor)
};

// Newton from (x, p) on G(x, p) = 0 and  row_x . x + row_p p = target:
//   [ G_x    G_p   ] [dx]     [ G ]
//   [ row_x  row_p ] [dp] = - [ g ],   g = row_x . x + row_p p - target.
// `linearise(x, p, why)` gives the iterate's BorderedLinearisation (G and the matrix above), or
// nullptr and why. Each step's solve is asked for the Eisenstat-Walker forcing term of
// orbit_shooting.hpp from |G|_2 (a direct solve ignores it). Converged when |G|_inf <= tolerance
// (1 + |x|_inf) and g is at its rounding level; then the tangent solves the same matrix with
// e_{n+1} (to `forcing.tangent`), normalised in the norm weight |z_x|^2 + z_p^2. Returns nullopt and
// the reason on failure: not converged in max_iterations, diverging (the residual 1e3 times
// above the one after the first step: not any growth, since near grazing the discrete problem is
// only piecewise smooth and an iterate may raise |G| before converging, and the start may have
// |G| = 0 with the constraint violated), a failed solve, a residual that cannot be formed.
// `work` accumulates the linearisations' factorisations and products. In the library
// (continuation_branch.cpp): compiled once, not per model.
using Linearise =
    std::function<std::unique_ptr<BorderedLinearisation>(const Eigen::VectorXd& x, double p, std::string& why)>;
std::optional<BranchState> bordered_corrector(const Linearise& linearise, Eigen::VectorXd x, double p,
                                              const Eigen::VectorXd& row_x, double row_p, double target,
                                              int max_iterations, double tolerance, double weight,
                                              const CorrectorForcing& forcing, std::string& why, double& seconds,
                                              CorrectorWork& work);

// G_p at p by the central difference (G(p + delta) - G(p - delta)) / (2 delta), delta = eps^(1/3)
// max(|p|, scale) (continuation.hpp: why that is enough). `residual_at(q)` is G at q and throws
// BadInput where the model rejects q: at a bound of the key's range (milling's depth from 0: p -
// delta = -6e-9 is rejected) the one-sided second-order stencil on the side the model accepts,
// (-3 G(p) + 4 G(p + s) - G(p + 2 s)) / (2 s), s = +-delta: the same order, and truncation 2x
// the central one's. Neither side accepted: the model's reason (BadInput) passes through. In
// the library.
Eigen::VectorXd parameter_derivative(const std::function<Eigen::VectorXd(double)>& residual_at, double p,
                                     const Eigen::VectorXd& G, double scale);

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
