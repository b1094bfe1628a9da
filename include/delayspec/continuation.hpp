#pragma once
// Pseudo-arclength continuation of the discrete periodic orbit in one scalar parameter p, with
// detection and location of its bifurcations (issue 15).
//
// The problem. X = (x, p), x the K states of one stroboscopic map (orbit_newton.hpp), and
//
//   F(x, p) = 0                           (the discrete periodic problem at parameter p)
//   <t, X - X_pred>_w = 0                 (the pseudo-arclength condition)
//
// with the weighted inner product <(x, p), (y, q)>_w = x.y / K + p q (the state part is the mean
// square over the map, so a step ds is comparable to a change of p). Predictor X_pred = X_i +
// ds t_i along the unit tangent t_i; corrector: Newton on the bordered system
//
//   [ F_x        F_p ] [dx]      [ F ]
//   [ t_x^T / K  t_p ] [dp]  = - [ g ],      g = <t, X - X_pred>_w,
//
// solved by GMRES on the system condensed onto the map's history, matrix-free with the step maps
// of the residual's evaluation (detail/condensed_bordered.hpp: what nested shooting does for
// M - I, with Eisenstat-Walker forcing terms), or factored whole with UMFPACK (sparse_lu.hpp; the
// border is one dense row and column, n + 1 unknowns): ContinuationSolver. Both solve the same
// system, so the Newton iterates and the points agree to the corrector's tolerance; the LU's
// factors fill in with a fractional delay (scripts/continuation_solver_cost.py measures both).
// Bordered, the matrix stays regular at a fold, where F_x is singular: the branch passes turning
// points (p may go back). The tangent at a new point solves the same matrix with
// the right-hand side e_{n+1} (orientation kept: <t_new, t_old>_w > 0).
//
// F_p. The model concept has no derivative with respect to a parameter, and the parameter may be
// any model key (a gap, a gain, a frequency that changes the step h), so F_p is the central
// difference (F(x, p + delta) - F(x, p - delta)) / (2 delta), delta = eps^(1/3) max(|p|, |to -
// from|): truncation delta^2 |F_ppp| / 6 plus rounding eps |F| / delta, both ~ 1e-11 relative.
// At a bound of the key's range (p - delta or p + delta rejected by the model) the one-sided
// second-order difference on the other side: the same order.
// Why that is enough: F_p enters only the Newton matrix and the tangent, never the equations a
// point satisfies. A point is accepted when |F(x, p)|_inf <= tolerance (1 + |x|_inf), whatever
// F_p; an F_p error of 1e-11 makes Newton's contraction factor ~1e-11 instead of 0 (still
// converged in the same number of steps) and tilts the predictor by 1e-11. The located
// bifurcations are zeros of test functions evaluated on exact solutions of F = 0.
//
// Step control (Newton's convergence): a corrector that converges in <= 3 iterations grows the
// next step by 1.5 (at most step_max); 6 or more shrink it by 0.7; one that fails (not converged
// in newton.max_iterations, the residual 1e3 times above the one after the first iteration, a
// singular matrix, a step the stepper cannot take), whose tangent turns by more than ~37 degrees (cos < 0.8: a jump to
// another branch is the usual cause), or whose secant turns back against the previous one (a corner of a piecewise-
// smooth branch, where the branch would retrace itself) is retried with half the step. A step
// below step_min ends the branch with `failure` set: the point reached and the reason (the
// points so far are kept).
//
// End of the branch: the first point past `to`, or back past `from` after a fold, is replaced
// by the point at exactly that end (Newton with p fixed); or max_points points. A predictor past
// `to` is first shortened to land on it. A parameter value the model rejects (BadInput from the
// model factory, e.g. a negative damping) counts as a failed corrector: the step shrinks, and the
// branch ends at the edge of the model's domain with `failure` set.
//
// At every point: the leading multipliers (floquet.hpp, the options' nev and solver), the number
// of unstable ones (|mu| > 1), the orbit's measures (OrbitMeasures). When the eigensolver fails
// (a pair failing its residual gate: in practice one of the smallest, |mu| ~ 1e-7, of a nearly
// rank-deficient monodromy) it is retried with one multiplier fewer, down to one; such a point
// has fewer than nev multipliers.
//
// Detection between consecutive points a, b (counts of multipliers outside the unit circle):
//   fold             the parameter turns (dp/ds changes sign; located where dp/ds = 0, which for
//                    the discrete problem is where F_x is singular, a multiplier +1; at a corner of
//                    a piecewise-smooth branch there is none, and the note says so), or the
//                    number of real multipliers > 1 changes parity (a branch point);
//   period-doubling  the number of real multipliers < -1 changes parity;
//   neimark-sacker   the number of non-real multipliers outside the circle changes and so does
//                    the number of unstable ones (a real pair becoming complex outside the
//                    circle changes the first only);
//   grazing          switching models: the sign of max H over the orbit changes, or, on an orbit
//                    in contact, the sign of the second hump's max H (a second contact region,
//                    OrbitMeasures::second_max_H; the bifurcation's note says which).
// Location: on the segment's own curve s -> X(s) (the corrector from X_a + s t_a on the
// hyperplane <t_a, X - X_a - s t_a>_w = 0, s in [0, s_b]), the zero of the test function
//   fold: dp/ds at a turning point, else mu - 1 for the real positive multiplier nearest 1;
//   period doubling: |mu| - 1 for the real negative one nearest -1; Neimark-Sacker: |mu| - 1 for
//   the non-real one nearest the circle; grazing: max H (a second region: second_max_H),
// first by bisection on the detection counts until the test function changes sign (a long
// segment may also hold a collision), then by the Illinois variant of regula falsi until the
// bracket's two ends differ by <= tolerance in p (a test function crossing transversally:
// superlinear). Where the corrector fails on one side (near grazing the discrete problem is only
// piecewise smooth and Newton may stall in contact), the root is the secant through the last two
// points of the other side, accepted when it moves by <= tolerance (`note` says so). A multiplier is real when |Im mu|
// <= 1e-10 |mu|. Only the nev leading multipliers are watched: more than nev outside the circle make the counts wrong.
//
// Errors: BadInput for invalid options (from == to, steps <= 0 or step_min > step_max, max_points
// < 2, a parameter that changes the size of the problem); NumericalFailure when the start (Newton
// at p = from) fails, naming the residual. A failure later ends the branch (result.failure).
//
// Example (a model factory: the model at parameter value p):
//   ContinuationOptions o;  o.from = -1.5;  o.to = -2.5;  o.N = 200;
//   auto result = continue_orbit<LinearModel>([](double b) { return LinearModel({-1, b, tau, tau}); },
//                                             Eigen::VectorXd::Zero(200), o);
//   // result.bifurcations[0]: neimark-sacker at b ~ -2, angle ~ 2 pi / 3
#include <cmath>
#include <complex>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "delayspec/errors.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/grid.hpp"
#include "delayspec/model_grid.hpp"
#include "delayspec/orbit_newton.hpp"
#include "delayspec/richardson.hpp"
#include "delayspec/stepper.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec {

enum class BifurcationType { fold, period_doubling, neimark_sacker, grazing };
// "fold", "period-doubling", "neimark-sacker", "grazing".
std::string to_string(BifurcationType type);
// The bifurcation at which the multiplier mu crosses the unit circle: a fold where mu is real and
// positive, a period doubling where real and negative, a Neimark-Sacker bifurcation where it is
// not real (real: |Im mu| <= 1e-10 |mu|, the tolerance continuation detects crossings with).
BifurcationType crossing_type(std::complex<double> mu);

// Measures of one periodic orbit (the states of one map, periodic).
struct OrbitMeasures {
  std::vector<double> max, min;  // per state component, over the grid nodes
  // Switching models (NaN otherwise): max of H over the orbit, between the nodes from the cubic
  // Hermite interpolant of H(y(t)) with the slopes grad H . f at the nodes (error O(h^4) beyond
  // the discrete orbit's own O(h^2), so the grazing point converges at second order), and the
  // time per map spent in region 1 (H > 0), from the event times of each step.
  double max_H = NAN;
  double contact_time = NAN;
  // The highest hump of H apart from the highest one, separated from it by free flight
  // (detail/contact_peaks.hpp; -infinity when there is none): on an orbit in contact its rise
  // through 0 is the grazing of a second contact region. contact_regions: the regions in contact.
  double second_max_H = NAN;
  int contact_regions = 0;
};

struct ContinuationPoint {
  double parameter = 0;
  std::vector<std::complex<double>> multipliers;  // leading, by modulus
  int unstable = 0;                               // multipliers with |mu| > 1
  bool stable() const { return unstable == 0; }
  OrbitMeasures measures;
  int newton_iterations = 0;  // corrector iterations that produced the point
  double step = 0;            // arclength step from the previous point (0 for the first)
  double residual = 0;        // |F|_inf at the point
  double tangent_p = 0;       // dp/ds of the unit tangent (oriented along the branch): 0 at a fold
  // An orbit of unknown period (hopf_branch.hpp): its period, and the trivial multiplier (the
  // time shift's, 1 to rounding: not among `multipliers`). NaN for a forced orbit.
  double period = NAN;
  std::complex<double> trivial_multiplier{NAN, NAN};
};

struct Bifurcation {
  BifurcationType type = BifurcationType::fold;
  double parameter = 0;
  std::vector<std::complex<double>> multipliers;  // at the located point
  double angle = 0;                               // arg of the critical multiplier, in [0, pi] (grazing: NaN)
  OrbitMeasures measures;
  long after_point = 0;   // index of the branch point before it
  double bracket = 0;     // width in p of the final bracket (<= tolerance unless `note` says)
  int evaluations = 0;    // corrected points evaluated to locate it
  std::string note;       // e.g. why the bracket stayed wider than the tolerance
  Eigen::VectorXd orbit;  // the sequence x at the located point (continue_period_doubled starts there)
  double period = NAN;    // an orbit of unknown period: its period there (the last entry of `orbit`)
};

// The parameter range and step control of a branch (continue_orbit, continue_equilibrium).
struct BranchRange {
  double from = 0, to = 1;  // the parameter range; the branch starts at `from`
  double step = 0;          // initial arclength step; 0 = |to - from| / 50
  double step_min = 0;      // 0 = 1e-6 |to - from|
  double step_max = 0;      // 0 = |to - from| / 10
  int max_points = 1000;    // branch points at most (the start included), >= 2
  double tolerance = 0;     // location tolerance in p; 0 = 1e-10 |to - from|
  // With error bars (the locations extrapolated): once a location's bracket is within
  // `tolerance`, it is narrowed on towards this while that works, at most 8 more corrected points
  // and none failing (near a grazing the corrector may not converge on one side); the bracket
  // reached is the location's accuracy (Bifurcation::bracket). 0: not (orbit branches only).
  double refine_tolerance = 0;
};
// The range with the defaults for 0 filled in, the step clamped to [step_min, step_max].
// BadInput naming the field: from or to not finite, an empty range, a step or tolerance <= 0,
// step_min > step_max, max_points < 2.
BranchRange checked_range(const BranchRange& range);

// How the corrector solves its bordered Newton systems (header): a sparse LU of the whole
// (UMFPACK), GMRES on the system condensed onto the map's history (matrix-free: no matrix is
// assembled or factored, detail/condensed_bordered.hpp), or automatic: GMRES, and the LU for a
// solve GMRES fails on (a strongly unstable orbit). Why GMRES first at every size: it was faster
// at every size measured, from d K = 100 (1.1x, aligned delay) to 3308 (62x, fractional delay;
// scripts/continuation_solver_cost.py, docs/continuation.md), with the same points.
enum class ContinuationSolver { automatic, krylov, lu };
// "auto", "krylov", "lu".
std::string to_string(ContinuationSolver solver);

struct ContinuationOptions : BranchRange {
  OrbitByNewtonOptions newton{1e-12, 10};  // corrector: relative residual, iterations per point
  ContinuationSolver solver = ContinuationSolver::automatic;
  // GMRES: Eisenstat-Walker's eta_max. Tighter than nested shooting's 1e-4: an iteration of the
  // corrector costs three nonlinear residuals (F and F_p's two), more than the few GMRES products
  // a tighter solve adds, and with 1e-6 the corrector takes the sparse LU's iterations (so the
  // same steps); measured on the PWSDDE and tau = T/2 branches at N = 800: 1e-4 took 106 iterations
  // where the LU takes 80, 1e-6 80, in the same time.
  double forcing_max = 1e-6;
  int gmres_restart = 40;          // GMRES: basis vectors per cycle
  int gmres_max_iterations = 400;  // GMRES: products per solve
  int start_iterations = 30;               // Newton iterations allowed for the first point
  FloquetOptions floquet;
  bool locate = true;  // locate the bifurcations detected (false: points only)
  // The discretisation.
  int N = 100;
  int periods_per_map = 1;  // period-p orbits
  StepOptions step_options;
  // Called after every accepted point (e.g. progress); may be empty.
  std::function<void(const ContinuationPoint&)> on_point;
};

// Where a branch ended.
enum class BranchEnd {
  to,          // at `to`
  from,        // back at `from` (turned back past the start)
  max_points,  // after max_points points
  failure      // it could not go on: ContinuationResult::failure says where and why
};
// "to", "from", "max_points", "failure".
std::string to_string(BranchEnd end);

struct ContinuationResult {
  std::vector<ContinuationPoint> points;
  std::vector<Bifurcation> bifurcations;  // by segment along the branch (within one: multiplier types first)
  BranchEnd end = BranchEnd::max_points;
  std::string failure;  // when end == failure: the point reached and the reason
  // Cost: corrector iterations (each one linearisation and one linear solve), the sparse LU
  // factorisations and GMRES products (one linearised map each) of their solves, eigensolves.
  long unknowns = 0;  // of the discrete problem: d K (an orbit of unknown period: d K + 1)
  long newton_iterations = 0;
  long factorisations = 0;
  long gmres_products = 0;
  long krylov_solves = 0;
  double newton_seconds = 0, krylov_seconds = 0, locate_seconds = 0, seconds = 0;
};

// The bifurcations of one type near one location, across N, and their extrapolation.
struct BifurcationEstimate {
  BifurcationType type = BifurcationType::fold;
  std::vector<int> Ns;               // the levels where it was found (increasing)
  std::vector<double> parameters;    // its location at each of them
  double parameter = 0;              // at the finest N
  double extrapolated = 0;           // Richardson (richardson.hpp), = parameter with one level
  double error_estimate = INFINITY;  // of `extrapolated`; infinity with one level
  double observed_order = NAN;       // log(d1 / d2) / log(r) of the last three levels
  double angle = 0;                  // at the finest N
  // Neimark-Sacker: the angle at each level extrapolated as the location is (NaN otherwise, and
  // the estimate infinite with one level): the angle of the N -> infinity point.
  std::vector<double> angles;  // at each of Ns
  double angle_extrapolated = NAN, angle_error_estimate = INFINITY;
  std::string note;
};

// Matches the bifurcations found at each N (by_N[i] at Ns[i], Ns increasing) to those at the
// finest N (same type, nearest parameter, each used once) and extrapolates each to h -> 0
// (h = 1 / N; the trapezoid rule's expansion h^2, h^4, ...: `richardson`). location_accuracy:
// the absolute accuracy of each location (the continuation tolerance; a location whose bracket
// stayed wider is known to its bracket), the floor of the error estimate. BadInput: sizes
// differ, Ns not increasing.
std::vector<BifurcationEstimate> extrapolate_bifurcations(const std::vector<int>& Ns,
                                                          const std::vector<std::vector<Bifurcation>>& by_N,
                                                          double location_accuracy,
                                                          const RichardsonOptions& richardson = {});

namespace continuation_detail {
class BranchProblem;  // the problem along a branch (detail/branch_corrector.hpp)
template <class Model, class ModelAt>
class PeriodicBranch;  // a forced orbit's (detail/periodic_branch.hpp)
// The options with the defaults relative to the range filled in (continuation.hpp), checked.
// BadInput naming the option for an empty range, a non-positive step or tolerance, step_min >
// step_max, max_points < 2.
ContinuationOptions checked_options(const ContinuationOptions& options);
// The tracer behind every continue_* (detail/continuation_branch.hpp, compiled in the library):
// the branch of `branch` from `guess` at p = options.from (Newton there), or, when start_tangent
// is given, from the point (guess, start_p) itself along that tangent (no Newton: the point may
// be singular, e.g. a period doubling seen by the doubled problem, a Hopf point), the first
// segment not searched. `branch` must have been built with checked_options(options).
ContinuationResult trace_branch(const BranchProblem& branch, const Eigen::VectorXd& guess,
                                const ContinuationOptions& options, const Eigen::VectorXd* start_tangent,
                                double start_p);
}  // namespace continuation_detail

// The branch through the periodic orbit near `guess` (a sequence, PeriodicOrbitProblem, at
// p = options.from; for a linear model the zero sequence). ModelAt: double -> Model.
template <class Model, class ModelAt>
ContinuationResult continue_orbit(const ModelAt& model_at, const Eigen::VectorXd& guess,
                                  const ContinuationOptions& options) {
  const ContinuationOptions o = continuation_detail::checked_options(options);
  const continuation_detail::PeriodicBranch<Model, ModelAt> branch(model_at, o);
  return continuation_detail::trace_branch(branch, guess, o, nullptr, o.from);
}

// The period-2 branch born at a period doubling `at` of the branch continue_orbit traced with
// `options` (its orbit: at.orbit). The doubled problem (periods_per_map twice the options') has
// the period-1 orbit repeated twice as a solution, singular at the period doubling (multiplier
// (-1)^2 = 1); its null vector w is the critical Floquet mode carried over two periods, which
// flips sign after one (w_{l+K} = -w_l). The branch leaves along t = (w, 0): the hyperplane
// <t, X - X_0 - s t>_w = 0 meets the period-2 branch and not the repeated period-1 orbits (they
// are orthogonal to an antiperiodic w). w is formed by a difference quotient of two runs of the
// doubled map from U* and U* + eps v (v the real eigenvector of -1, eps = 1e-7 |U*|): a direction
// only, its O(eps) error moves no result. The segment leaving the period doubling is not searched
// for bifurcations (its multiplier +1 is the bifurcation itself). Then as continue_orbit, within
// [from, to] (either end).
// BadInput: `at` is not a located period doubling (no orbit, or the wrong size).
template <class Model, class ModelAt>
ContinuationResult continue_period_doubled(const ModelAt& model_at, const Bifurcation& at,
                                           const ContinuationOptions& options) {
  using Map = StroboscopicMap<Model>;
  if (at.type != BifurcationType::period_doubling || at.orbit.size() == 0)
    throw BadInput("continue_period_doubled: needs a located period doubling with its orbit");
  const Model model = model_at(at.parameter);
  const StepOptions& so = options.step_options;
  const int N = options.N, periods = options.periods_per_map;
  const Map map1(TrapezoidStepper<Model>(model, so), model_grid(model, N, periods, so.grid));
  const Map map2(TrapezoidStepper<Model>(model, so), model_grid(model, N, 2 * periods, so.grid));
  const PeriodicOrbitProblem<Map> problem1(map1);
  if (at.orbit.size() != problem1.unknowns())
    throw BadInput("continue_period_doubled: the orbit has " + std::to_string(at.orbit.size()) + " entries, expected " +
                   std::to_string(problem1.unknowns()));
  const Eigen::VectorXd U = problem1.history(at.orbit);
  // The real eigenvector of the multiplier nearest -1.
  FloquetOptions fo = options.floquet;
  fo.keep_vectors = true;
  if (fo.solver != FloquetSolver::arpack) fo.solver = FloquetSolver::spectra;  // eigenvectors: Krylov only
  const FloquetResult r = floquet_multipliers(map1.monodromy(U), fo);
  size_t k = 0;
  for (size_t i = 1; i < r.multipliers.size(); ++i)
    if (std::abs(r.multipliers[i] + 1.0) < std::abs(r.multipliers[k] + 1.0)) k = i;
  if (r.subspace.cols() <= static_cast<long>(k))
    throw NumericalFailure("continue_period_doubled: no eigenvector for the multiplier " +
                           format_number(r.multipliers[k].real()));
  const Eigen::VectorXd v = r.subspace.col(static_cast<long>(k)).normalized();
  const double eps = 1e-7 * std::max(1.0, U.lpNorm<Eigen::Infinity>());
  std::vector<Vec<Model::d>> base, moved;
  map2.apply(U, nullptr, &base);
  map2.apply(U + eps * v, nullptr, &moved);
  const long K2 = map2.grid().K;
  Eigen::VectorXd x0(static_cast<long>(Model::d) * K2), tangent(static_cast<long>(Model::d) * K2 + 1);
  for (long l = 0; l < K2; ++l) {
    x0.segment<Model::d>(Model::d * l) = base[static_cast<size_t>(l)];
    tangent.segment<Model::d>(Model::d * l) = (moved[static_cast<size_t>(l)] - base[static_cast<size_t>(l)]) / eps;
  }
  tangent[tangent.size() - 1] = 0;
  ContinuationOptions o2 = options;
  o2.periods_per_map = 2 * options.periods_per_map;
  const ContinuationOptions checked = continuation_detail::checked_options(o2);
  const continuation_detail::PeriodicBranch<Model, ModelAt> branch(model_at, checked);
  return continuation_detail::trace_branch(branch, x0, checked, &tangent, at.parameter);
}

}  // namespace delayspec

// The implementation: the discrete problem at one parameter (the tracer and the locator are
// compiled in the library: src/engine/continuation_branch.cpp).
#include "delayspec/detail/periodic_branch.hpp"
