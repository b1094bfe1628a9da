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
// factored whole with UMFPACK (sparse_lu.hpp; the border is one dense row and column, n + 1
// unknowns). Bordered, the matrix stays regular at a fold, where F_x is singular: the branch
// passes turning points (p may go back). The tangent at a new point solves the same matrix with
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
//   grazing          switching models: the sign of max H over the orbit changes.
// Location: on the segment's own curve s -> X(s) (the corrector from X_a + s t_a on the
// hyperplane <t_a, X - X_a - s t_a>_w = 0, s in [0, s_b]), the zero of the test function
//   fold: dp/ds at a turning point, else mu - 1 for the real positive multiplier nearest 1;
//   period doubling: |mu| - 1 for the real negative one nearest -1; Neimark-Sacker: |mu| - 1 for
//   the non-real one nearest the circle; grazing: max H,
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
#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "delayspec/errors.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/grid.hpp"
#include "delayspec/orbit_newton.hpp"
#include "delayspec/richardson.hpp"
#include "delayspec/detail/sparse_lu.hpp"
#include "delayspec/stepper.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec {

enum class BifurcationType { fold, period_doubling, neimark_sacker, grazing };
// "fold", "period-doubling", "neimark-sacker", "grazing".
std::string to_string(BifurcationType type);

// Measures of one periodic orbit (the states of one map, periodic).
struct OrbitMeasures {
  std::vector<double> max, min;  // per state component, over the grid nodes
  // Switching models (NaN otherwise): max of H over the orbit, between the nodes from the cubic
  // Hermite interpolant of H(y(t)) with the slopes grad H . f at the nodes (error O(h^4) beyond
  // the discrete orbit's own O(h^2), so the grazing point converges at second order), and the
  // time per map spent in region 1 (H > 0), from the event times of each step.
  double max_H = NAN;
  double contact_time = NAN;
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
};

struct ContinuationOptions {
  double from = 0, to = 1;                 // the parameter range; the branch starts at `from`
  double step = 0;                         // initial arclength step; 0 = |to - from| / 50
  double step_min = 0;                     // 0 = 1e-6 |to - from|
  double step_max = 0;                     // 0 = |to - from| / 10
  int max_points = 1000;                   // branch points at most (the start included), >= 2
  double tolerance = 0;                    // location tolerance in p; 0 = 1e-10 |to - from|
  OrbitByNewtonOptions newton{1e-12, 10};  // corrector: relative residual, iterations per point
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

struct ContinuationResult {
  std::vector<ContinuationPoint> points;
  std::vector<Bifurcation> bifurcations;  // by segment along the branch (within one: multiplier types first)
  std::string end;                        // "to", "from" (turned back past the start), "max_points", or "failure"
  std::string failure;                    // when end == "failure": the point reached and the reason
  // Cost: corrector iterations (each one linearisation + one sparse LU) and Krylov solves.
  long newton_iterations = 0;
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
  std::string note;
};

// Matches the bifurcations found at each N (by_N[i] at Ns[i], Ns increasing) to those at the
// finest N (same type, nearest parameter, each used once) and extrapolates each to h -> 0
// (h = 1 / N; the trapezoid rule's expansion h^2, h^4, ...: `richardson`). location_accuracy:
// the absolute accuracy of each location (the continuation tolerance), the floor of the error
// estimate. BadInput: sizes differ, Ns not increasing.
std::vector<BifurcationEstimate> extrapolate_bifurcations(const std::vector<int>& Ns,
                                                          const std::vector<std::vector<Bifurcation>>& by_N,
                                                          double location_accuracy,
                                                          const RichardsonOptions& richardson = {});

namespace continuation_detail {

// The continued key changed the size of the discrete problem (e.g. a period that changes K): bad
// input, not a point outside the model's domain (which ends the branch).
class ProblemSizeChanged : public BadInput {
 public:
  using BadInput::BadInput;
};

// Multipliers outside the unit circle, by kind (the detection counts of the header).
struct UnstableCounts {
  int real_plus = 0, real_minus = 0, complex = 0;
  int total() const { return real_plus + real_minus + complex; }
};
bool is_real(std::complex<double> mu);
UnstableCounts unstable_counts(const std::vector<std::complex<double>>& multipliers);
// The bifurcations (without grazing) whose counts change from a to b.
std::vector<BifurcationType> detected_changes(const UnstableCounts& a, const UnstableCounts& b);
// The test function of `type` (header), NaN when the point has no candidate multiplier; the
// critical multiplier in *critical.
double multiplier_test(BifurcationType type, const std::vector<std::complex<double>>& multipliers,
                       std::complex<double>* critical = nullptr);
// The maximum of the cubic Hermite interpolant on [0, h] of values g0, g1 and slopes s0, s1.
double hermite_maximum(double g0, double g1, double s0, double s1, double h);

}  // namespace continuation_detail

// The branch through the periodic orbit near `guess` (a sequence, PeriodicOrbitProblem, at
// p = options.from; for a linear model the zero sequence). ModelAt: double -> Model.
template <class Model, class ModelAt>
ContinuationResult continue_orbit(const ModelAt& model_at, const Eigen::VectorXd& guess,
                                  const ContinuationOptions& options);

// ---------------------------------------------------------------------------------------------
// Implementation.

template <class Model, class ModelAt>
class PeriodicBranch {
 public:
  static constexpr int D = Model::d;
  using V = Vec<D>;
  using Map = StroboscopicMap<Model>;

  // A corrected point with the tangent there.
  struct State {
    Eigen::VectorXd x;
    double p = 0;
    Eigen::VectorXd tx;  // unit tangent (weighted norm)
    double tp = 0;
    int iterations = 0;
    double residual = 0;
  };

  PeriodicBranch(const ModelAt& model_at, const ContinuationOptions& o) : model_at_(model_at), o_(o) {
    const HistoryGrid g = grid_at(o.from);
    K_ = g.K;
    M_ = g.M;
    weight_ = 1.0 / static_cast<double>(K_);
    range_ = std::abs(o.to - o.from);
  }

  long unknowns() const { return static_cast<long>(D) * K_; }

  Map map_at(double p) const {
    const Model model = model_at_(p);
    const HistoryGrid g = grid_at_model(model, p);
    return Map(TrapezoidStepper<Model>(model, o_.step_options), g);
  }

  // Newton from (x, p) on F = 0 and  row_x . x + row_p p = target. On success the tangent
  // oriented by the row (row . t > 0). Returns nullopt and the reason on failure.
  std::optional<State> correct(Eigen::VectorXd x, double p, const Eigen::VectorXd& row_x, double row_p, double target,
                               int max_iterations, std::string& why, double& seconds) const {
    const auto start = std::chrono::steady_clock::now();
    struct Timer {
      std::chrono::steady_clock::time_point start;
      double& seconds;
      ~Timer() { seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); }
    } timer{start, seconds};
    const long n = unknowns();
    double first = INFINITY;
    for (int it = 0;; ++it) {
      Eigen::VectorXd F, Fp;
      Eigen::SparseMatrix<double> Fx;
      try {
        linearise(x, p, F, Fx, Fp);
      } catch (const NumericalFailure& e) {
        why = std::string("residual not computable at ") + format_number(p) + " (" + e.what() + ")";
        return std::nullopt;
      } catch (const continuation_detail::ProblemSizeChanged&) {
        throw;
      } catch (const BadInput& e) {  // p (or p +- delta) outside the model's domain
        why = std::string("the model rejects parameter ") + format_number(p) + " (" + e.what() + ")";
        return std::nullopt;
      }
      const double r = F.lpNorm<Eigen::Infinity>();
      const double g = row_x.dot(x) + row_p * p - target;
      if (!std::isfinite(r)) {
        why = "non-finite residual, |F|_inf = " + format_number(r) + " at parameter " + format_number(p);
        return std::nullopt;
      }
      // g is linear: after one Newton step it is at its rounding level, eps times the size of its terms
      const double g_scale = row_x.cwiseAbs().dot(x.cwiseAbs()) + std::abs(row_p * p) + std::abs(target);
      const bool converged =
          r <= o_.newton.tolerance * (1 + x.lpNorm<Eigen::Infinity>()) && std::abs(g) <= 1e-12 * (1 + g_scale);
      // Diverging: the residual 1e3 times above the one after the first step (not any growth: near
      // grazing the discrete problem is only piecewise smooth and an iterate may raise |F| before
      // converging; the start may have |F| = 0 with the constraint violated).
      if (it == 1) first = r;
      if (!converged && (it >= max_iterations || r > 1e3 * first)) {
        why = (it >= max_iterations ? "not converged in " + std::to_string(it) + " iterations"
                                    : "residual diverging at iteration " + std::to_string(it)) +
              ", |F|_inf = " + format_number(r) + " at parameter " + format_number(p);
        return std::nullopt;
      }
      // The bordered matrix [F_x F_p; row_x^T row_p] (n + 1 square).
      std::vector<Eigen::Triplet<double>> triplets;
      triplets.reserve(static_cast<size_t>(Fx.nonZeros() + 2 * n + 1));
      for (int k = 0; k < Fx.outerSize(); ++k)
        for (Eigen::SparseMatrix<double>::InnerIterator e(Fx, k); e; ++e)
          triplets.emplace_back(static_cast<int>(e.row()), static_cast<int>(e.col()), e.value());
      for (long i = 0; i < n; ++i) {
        if (Fp[i] != 0) triplets.emplace_back(static_cast<int>(i), static_cast<int>(n), Fp[i]);
        if (row_x[i] != 0) triplets.emplace_back(static_cast<int>(n), static_cast<int>(i), row_x[i]);
      }
      triplets.emplace_back(static_cast<int>(n), static_cast<int>(n), row_p);
      Eigen::SparseMatrix<double> A(n + 1, n + 1);
      A.setFromTriplets(triplets.begin(), triplets.end());
      A.makeCompressed();
      std::optional<SparseLU> lu;
      try {
        lu.emplace(A);
      } catch (const NumericalFailure& e) {
        why = std::string("bordered matrix singular at parameter ") + format_number(p) + " (" + e.what() + ")";
        return std::nullopt;
      }
      Eigen::VectorXd rhs(n + 1);
      if (converged) {
        // The tangent: [F_x F_p; row] z = e_{n+1}.
        rhs.setZero();
        rhs[n] = 1;
        const Eigen::VectorXd z = lu->solve(rhs);
        const double norm = std::sqrt(weight_ * z.head(n).squaredNorm() + z[n] * z[n]);
        State s;
        s.x = std::move(x);
        s.p = p;
        s.tx = z.head(n) / norm;
        s.tp = z[n] / norm;
        s.iterations = it;
        s.residual = r;
        return s;
      }
      rhs.head(n) = -F;
      rhs[n] = -g;
      const Eigen::VectorXd step = lu->solve(rhs);
      x += step.head(n);
      p += step[n];
    }
  }

  // F(x, p), F_x and F_p (central difference, header).
  void linearise(const Eigen::VectorXd& x, double p, Eigen::VectorXd& F, Eigen::SparseMatrix<double>& Fx,
                 Eigen::VectorXd& Fp) const {
    const Map map = map_at(p);
    F = PeriodicOrbitProblem<Map>(map).residual(x, &Fx);
    const double delta = std::cbrt(std::numeric_limits<double>::epsilon()) * std::max({std::abs(p), range_, 1e-300});
    const double up = p + delta, down = p - delta;
    // At a bound of the key's range (milling's depth from 0: p - delta = -6e-9 is rejected) the
    // one-sided second-order stencil on the side the model accepts, (-3 F(p) + 4 F(p + s) -
    // F(p + 2 s)) / (2 s), s = +-delta: the same order, and truncation 2x the central one's.
    auto map_if_accepted = [&](double q) -> std::optional<Map> {
      try {
        return map_at(q);
      } catch (const BadInput&) {
        return std::nullopt;
      }
    };
    auto residual = [&](const Map& m) { return PeriodicOrbitProblem<Map>(m).residual(x); };
    const std::optional<Map> map_up = map_if_accepted(up), map_down = map_if_accepted(down);
    if (map_up && map_down) {
      Fp = (residual(*map_up) - residual(*map_down)) / (up - down);
      return;
    }
    if (!map_up && !map_down) map_at(down);  // neither side: the model's reason (BadInput)
    const double side = map_up ? delta : -delta;
    const double s1 = (p + side) - p, s2 = (p + 2 * side) - p;  // the steps as represented
    const Eigen::VectorXd F1 = residual(map_up ? *map_up : *map_down), F2 = residual(map_at(p + 2 * side));
    // Quadratic through (0, F), (s1, F1), (s2, F2), differentiated at 0.
    Fp = (-(s1 + s2) / (s1 * s2)) * F + (s2 / (s1 * (s2 - s1))) * F1 - (s1 / (s2 * (s2 - s1))) * F2;
  }

  // Weighted inner product of the state parts plus the parameters' product.
  double dot(const Eigen::VectorXd& ax, double ap, const Eigen::VectorXd& bx, double bp) const {
    return weight_ * ax.dot(bx) + ap * bp;
  }
  double weight() const { return weight_; }

  // Multipliers and measures of the orbit x at p.
  ContinuationPoint evaluate(const State& s, double& krylov_seconds) const {
    ContinuationPoint point;
    point.parameter = s.p;
    point.newton_iterations = s.iterations;
    point.residual = s.residual;
    point.tangent_p = s.tp;
    const Map map = map_at(s.p);
    PeriodicOrbitProblem<Map> problem(map);
    const auto start = std::chrono::steady_clock::now();
    const auto monodromy = map.monodromy(problem.history(s.x));
    // A pair failing the residual gate is nearly always one of the smallest requested (|mu| ~ 1e-7
    // on a nearly rank-deficient monodromy, far below anything that crosses the circle): retried
    // with one multiplier fewer, down to one; the point has then fewer multipliers.
    FloquetOptions floquet = o_.floquet;
    FloquetResult r;
    for (;;) {
      try {
        r = floquet_multipliers(monodromy, floquet);
        break;
      } catch (const NumericalFailure&) {
        if (floquet.nev <= 1) throw;
        --floquet.nev;
      }
    }
    krylov_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    point.multipliers = r.multipliers;
    for (const auto& mu : r.multipliers) point.unstable += std::abs(mu) > 1;
    point.measures = measures(map, s.x);
    return point;
  }

  OrbitMeasures measures(const Map& map, const Eigen::VectorXd& x) const {
    OrbitMeasures m;
    const Eigen::Map<const Eigen::Matrix<double, D, Eigen::Dynamic>> states(x.data(), D, K_);
    for (int i = 0; i < D; ++i) {
      m.max.push_back(states.row(i).maxCoeff());
      m.min.push_back(states.row(i).minCoeff());
    }
    if constexpr (Model::has_switching) {
      const HistoryGrid& g = map.grid();
      const Model& model = map.stepper().model();
      const double theta = g.theta, c0 = 1 - theta, h = g.h;
      auto u = [&](long l) { return V(states.col(((l % K_) + K_) % K_)); };
      m.max_H = -INFINITY;
      m.contact_time = 0;
      StepMap<D> scratch;
      for (long l = 0; l < K_; ++l) {
        const V w0 = theta == 0 ? u(l - g.m) : V(c0 * u(l - g.m) + theta * u(l - g.m - 1));
        const V w1 = theta == 0 ? u(l - g.m + 1) : V(c0 * u(l - g.m + 1) + theta * u(l - g.m));
        const double t = static_cast<double>(l % g.steps_per_period) * h;
        const V a = u(l), b = u(l + 1);
        const int ja = region_of(model, a), jb = region_of(model, b);
        const V grad = model.grad_H(a);  // H affine (model.hpp)
        // max H on [t, t + h]: Hermite cubic through H and dH/dt = grad H . f at both nodes
        m.max_H = std::max(m.max_H,
                           continuation_detail::hermite_maximum(model.H(a), model.H(b), grad.dot(model.f(ja, t, a, w0)),
                                                                grad.dot(model.f(jb, t + h, b, w1)), h));
        // time in region 1 within the step, from its events (none with events off: the node's region)
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
    }
    return m;
  }

  const ContinuationOptions& options() const { return o_; }

 private:
  HistoryGrid grid_at(double p) const { return grid_at_model(model_at_(p), p); }
  HistoryGrid grid_at_model(const Model& model, double p) const {
    const HistoryGrid g = make_grid(model.tau(), model.period(), o_.N, o_.periods_per_map);
    if (K_ != 0 && (g.K != K_ || g.M != M_))
      throw continuation_detail::ProblemSizeChanged(
          "continuation: at parameter " + format_number(p) + " the grid has K = " + std::to_string(g.K) +
          ", M = " + std::to_string(g.M) + " (at the start K = " + std::to_string(K_) + ", M = " + std::to_string(M_) +
          "): the continued key must not change the size of the discrete problem");
    return g;
  }

  const ModelAt& model_at_;
  ContinuationOptions o_;
  long K_ = 0, M_ = 0;
  double weight_ = 1, range_ = 1;
};

namespace continuation_detail {
// The branch from `guess` at p = options.from (Newton there), or, when start_tangent is given,
// from the point (guess, start_p) itself along that tangent (no Newton: the point may be singular,
// e.g. a period doubling seen by the doubled problem), the first segment not searched.
template <class Model, class ModelAt>
ContinuationResult trace_branch(const ModelAt& model_at, const Eigen::VectorXd& guess,
                                const ContinuationOptions& options, const Eigen::VectorXd* start_tangent,
                                double start_p);
}  // namespace continuation_detail

template <class Model, class ModelAt>
ContinuationResult continue_orbit(const ModelAt& model_at, const Eigen::VectorXd& guess,
                                  const ContinuationOptions& options) {
  return continuation_detail::trace_branch<Model>(model_at, guess, options, nullptr, options.from);
}

template <class Model, class ModelAt>
ContinuationResult continuation_detail::trace_branch(const ModelAt& model_at, const Eigen::VectorXd& guess,
                                                     const ContinuationOptions& options,
                                                     const Eigen::VectorXd* start_tangent, double start_p) {
  using Branch = PeriodicBranch<Model, ModelAt>;
  using State = typename Branch::State;
  namespace cd = continuation_detail;
  const auto run_start = std::chrono::steady_clock::now();
  ContinuationOptions o = options;
  require_finite("continue_from", o.from);
  require_finite("continue_to", o.to);
  if (o.from == o.to) throw BadInput("`continue_from = continue_to = " + format_number(o.from) + "`: an empty range");
  const double range = std::abs(o.to - o.from), direction = o.to > o.from ? 1 : -1;
  if (o.step == 0) o.step = range / 50;
  if (o.step_min == 0) o.step_min = 1e-6 * range;
  if (o.step_max == 0) o.step_max = range / 10;
  if (o.tolerance == 0) o.tolerance = 1e-10 * range;
  require_positive("continue_step", o.step);
  require_positive("continue_step_min", o.step_min);
  require_positive("continue_step_max", o.step_max);
  require_positive("continue_tolerance", o.tolerance);
  if (o.step_min > o.step_max)
    throw BadInput("`continue_step_min = " + format_number(o.step_min) +
                   "` exceeds `continue_step_max = " + format_number(o.step_max) + "`");
  o.step = std::clamp(o.step, o.step_min, o.step_max);
  if (o.max_points < 2) throw BadInput("`continue_max_points = " + std::to_string(o.max_points) + "`: must be >= 2");

  Branch branch(model_at, o);
  const long n = branch.unknowns();
  if (guess.size() != n)
    throw BadInput("continuation: the start sequence has " + std::to_string(guess.size()) + " entries, expected " +
                   std::to_string(n));
  ContinuationResult result;
  const Eigen::VectorXd zero_row = Eigen::VectorXd::Zero(n);

  // The first point: Newton at p = from; the tangent towards `to`. Or the given point and tangent.
  std::string why;
  std::optional<State> current;
  if (start_tangent) {
    if (start_tangent->size() != n + 1)
      throw BadInput("continuation: the start tangent has " + std::to_string(start_tangent->size()) + " entries");
    State given;
    given.x = guess;
    given.p = start_p;
    const double norm =
        std::sqrt(branch.dot(start_tangent->head(n), (*start_tangent)[n], start_tangent->head(n), (*start_tangent)[n]));
    given.tx = start_tangent->head(n) / norm;
    given.tp = (*start_tangent)[n] / norm;
    current = std::move(given);
  } else {
    current = branch.correct(guess, o.from, zero_row, 1.0, o.from, o.start_iterations, why, result.newton_seconds);
  }
  if (!current)
    throw NumericalFailure("continuation start: Newton on the periodic orbit at parameter " + format_number(o.from) +
                           " failed: " + why);
  if (!start_tangent && current->tp * direction < 0) {
    current->tx = -current->tx;
    current->tp = -current->tp;
  }
  result.newton_iterations += current->iterations;
  auto add_point = [&](ContinuationPoint point) {
    ++result.krylov_solves;
    result.points.push_back(std::move(point));
    if (o.on_point) o.on_point(result.points.back());
  };
  add_point(branch.evaluate(*current, result.krylov_seconds));

  // The corrected point at arclength s from `base` along its tangent.
  auto point_along = [&](const State& base, double s, std::string& reason) {
    const Eigen::VectorXd pred_x = base.x + s * base.tx;
    const double pred_p = base.p + s * base.tp;
    const Eigen::VectorXd row_x = branch.weight() * base.tx;
    return branch.correct(pred_x, pred_p, row_x, base.tp, row_x.dot(pred_x) + base.tp * pred_p, o.newton.max_iterations,
                          reason, result.newton_seconds);
  };

  // Locates a bifurcation of `type` between base (point a) and b at arclength s_b along base's tangent.
  auto locate = [&](BifurcationType type, bool by_tangent, const State& base, const ContinuationPoint& pa,
                    const ContinuationPoint& pb, const Eigen::VectorXd& xb, double s_b, long after) {
    const auto locate_start = std::chrono::steady_clock::now();
    auto test = [&](const ContinuationPoint& pt) {
      if (type == BifurcationType::grazing) return pt.measures.max_H;
      if (by_tangent) return pt.tangent_p;  // a turning point: dp/ds through 0
      return cd::multiplier_test(type, pt.multipliers);
    };
    Bifurcation bif;
    bif.type = type;
    bif.after_point = after;
    // Samples on the negative and the positive side of the test function; the root lies between.
    struct Sample {
      double s, g, p;
      ContinuationPoint point;
      Eigen::VectorXd x;  // the orbit (a switch at a period doubling starts from it)
    };
    Sample neg{0, test(pa), pa.parameter, pa, base.x}, pos{s_b, test(pb), pb.parameter, pb, xb};
    // A long segment may hold more than the one crossing (a pair colliding on the real axis, the
    // multiplier nearest +-1 not being the one that crosses): bisect on the detection counts,
    // which are exact, until the test function changes sign over the sub-segment.
    const auto changes_here = [&](const ContinuationPoint& x, const ContinuationPoint& y) {
      if (by_tangent) return (x.tangent_p > 0) != (y.tangent_p > 0);
      const auto found = cd::detected_changes(cd::unstable_counts(x.multipliers), cd::unstable_counts(y.multipliers));
      return std::find(found.begin(), found.end(), type) != found.end();
    };
    while (type != BifurcationType::grazing && !(neg.g * pos.g < 0) && bif.evaluations < 60 &&
           std::abs(pos.p - neg.p) > o.tolerance) {
      const double s = 0.5 * (neg.s + pos.s);
      std::string reason;
      std::optional<State> st = point_along(base, s, reason);
      ++bif.evaluations;
      if (!st) break;
      result.newton_iterations += st->iterations;
      ++result.krylov_solves;
      ContinuationPoint mid;
      try {
        mid = branch.evaluate(*st, result.krylov_seconds);
      } catch (const NumericalFailure&) {
        break;
      }
      const Sample m{s, test(mid), mid.parameter, mid, st->x};
      if (changes_here(neg.point, mid)) pos = m;  // (neg, pos) keep the order of s until the sign change
      else neg = m;
    }
    if (neg.g > 0) std::swap(neg, pos);
    std::optional<Sample> prev_neg;       // the negative sample before `neg`
    double g_neg = neg.g, g_pos = pos.g;  // Illinois: possibly halved copies
    int side = 0;                         // which side moved last (Illinois)
    bool one_sided = false;               // a corrector failed on the positive side: secant from the negative side
    double located = NAN;                 // the root from the secant through prev_neg and neg
    if (!(neg.g < 0 && pos.g > 0)) {
      bif.note = "the test function does not change sign over the segment (" + format_number(neg.g) + ", " +
                 format_number(pos.g) + "): location by the nearer end";
    }
    auto secant_root = [&](double& s_root) {  // root of the line through prev_neg and neg
      if (!prev_neg || neg.g == prev_neg->g) return false;
      s_root = neg.s - neg.g * (neg.s - prev_neg->s) / (neg.g - prev_neg->g);
      return std::isfinite(s_root);
    };
    while (neg.g < 0 && pos.g > 0 && bif.evaluations < 60) {
      // Done: the bracket is within the tolerance, or the secant from the negative side puts the
      // root within the tolerance of `neg` (then the root is that extrapolation).
      if (std::abs(pos.p - neg.p) <= o.tolerance) break;
      double s_root;
      if (secant_root(s_root)) {
        const double p_root = neg.p + (s_root - neg.s) * (neg.p - prev_neg->p) / (neg.s - prev_neg->s);
        if (std::abs(p_root - neg.p) <= o.tolerance && (s_root - neg.s) * (pos.s - neg.s) >= 0) {
          located = p_root;
          break;
        }
      }
      const double lo = std::min(neg.s, pos.s), hi = std::max(neg.s, pos.s), margin = 1e-3 * (hi - lo);
      double s = (neg.s * g_pos - pos.s * g_neg) / (g_pos - g_neg);  // regula falsi
      if (one_sided) s = secant_root(s_root) && side != 1 ? s_root : 0.5 * (lo + hi);
      s = std::clamp(s, lo + margin, hi - margin);
      std::string reason;
      std::optional<State> st = point_along(base, s, reason);
      ++bif.evaluations;
      std::optional<ContinuationPoint> pt;
      double g = NAN;
      if (st) {
        result.newton_iterations += st->iterations;
        ++result.krylov_solves;
        try {
          pt = branch.evaluate(*st, result.krylov_seconds);
          g = test(*pt);
        } catch (const NumericalFailure& e) {
          reason = e.what();
        }
      }
      if (!pt || !std::isfinite(g)) {
        // Taken as the positive side (for grazing the side in contact, where the discrete problem
        // is least smooth); from now on the root comes from the negative side.
        one_sided = true;
        pos.s = s;
        side = 1;
        bif.note = "located from one side: " + (pt ? std::string("no candidate multiplier") : reason) +
                   " at s = " + format_number(s);
        continue;
      }
      if (g == 0) {
        neg = {s, g, pt->parameter, *pt, st->x};
        pos = neg;
        break;
      }
      if (g < 0) {
        prev_neg = neg;
        neg = {s, g, pt->parameter, *pt, st->x};
        g_neg = g;
        if (side == -1) g_pos *= 0.5;
        side = -1;
      } else {
        pos = {s, g, pt->parameter, *pt, st->x};
        g_pos = g;
        if (side == 1) g_neg *= 0.5;
        side = 1;
      }
    }
    const Sample& nearer = std::abs(neg.g) <= std::abs(pos.g) || one_sided ? neg : pos;
    const ContinuationPoint& best = nearer.point;
    bif.bracket = std::isfinite(located) ? std::abs(located - neg.p) : std::abs(pos.p - neg.p);
    if (bif.bracket > o.tolerance)
      bif.note += std::string(bif.note.empty() ? "" : "; ") + "bracket " + format_number(bif.bracket) +
                  " wider than the tolerance after " + std::to_string(bif.evaluations) + " evaluations";
    bif.parameter = std::isfinite(located) ? located : best.parameter;
    bif.multipliers = best.multipliers;
    bif.measures = best.measures;
    bif.orbit = nearer.x;
    std::complex<double> critical;
    if (type == BifurcationType::grazing) {
      bif.angle = NAN;
    } else if (std::isfinite(cd::multiplier_test(type, best.multipliers, &critical))) {
      bif.angle = std::abs(std::arg(critical));
      if (by_tangent && std::abs(critical - 1.0) > 1e-3)
        bif.note += std::string(bif.note.empty() ? "" : "; ") + "a turning point with no multiplier at +1 (nearest " +
                    format_number(critical.real()) + "): a nonsmooth fold";
    }
    result.bifurcations.push_back(std::move(bif));
    result.locate_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - locate_start).count();
  };

  double ds = o.step;
  std::optional<State> previous_state;  // the point before `current`
  result.end = "max_points";
  while (static_cast<long>(result.points.size()) < o.max_points) {
    // A predictor past `to` is shortened to land on it (the model may not exist beyond).
    if ((current->p + ds * current->tp - o.to) * direction > 0 && std::abs(current->tp) > 0.1)
      ds = std::max((o.to - current->p) / current->tp, o.step_min);
    std::string reason;
    std::optional<State> next = point_along(*current, ds, reason);
    if (next && branch.dot(next->tx, next->tp, current->tx, current->tp) < 0) {
      next->tx = -next->tx;  // keep the orientation
      next->tp = -next->tp;
    }
    if (next && branch.dot(next->tx, next->tp, current->tx, current->tp) < 0.8) {
      reason =
          "the tangent turned by " +
          format_number(std::acos(std::clamp(branch.dot(next->tx, next->tp, current->tx, current->tp), -1.0, 1.0))) +
          " rad";
      next.reset();
    }
    if (next && previous_state) {
      // The branch must not turn back on itself: consecutive secants at an angle above 90 degrees
      // (at a smooth fold the state keeps moving and the secants turn by O(ds)). Seen at a corner
      // of a piecewise-smooth branch (an impact grazing with |mu| -> 1), where the corrector beyond
      // the corner lands on the same branch behind it and the branch would retrace itself.
      const Eigen::VectorXd d1x = current->x - previous_state->x, d2x = next->x - current->x;
      const double d1p = current->p - previous_state->p, d2p = next->p - current->p;
      const double cosine =
          branch.dot(d1x, d1p, d2x, d2p) / std::sqrt(branch.dot(d1x, d1p, d1x, d1p) * branch.dot(d2x, d2p, d2x, d2p));
      if (cosine < 0) {
        reason = "the branch turns back on itself (consecutive secants at " +
                 format_number(std::acos(std::clamp(cosine, -1.0, 1.0))) + " rad: a corner, not a smooth fold)";
        next.reset();
      }
    }
    if (!next) {
      ds *= 0.5;
      if (ds < o.step_min) {
        const ContinuationPoint& last = result.points.back();
        result.end = "failure";
        result.failure = "step below continue_step_min = " + format_number(o.step_min) + " after point " +
                         std::to_string(result.points.size() - 1) + " at parameter " + format_number(last.parameter) +
                         " (" + reason + ")";
        break;
      }
      continue;
    }
    result.newton_iterations += next->iterations;
    double s_b = ds;
    bool last = false;
    // Past an end of the range: the point exactly at that end instead.
    const double past_to = (next->p - o.to) * direction, before_from = (o.from - next->p) * direction;
    if (past_to >= 0 || before_from > 0) {
      const double end_p = past_to >= 0 ? o.to : o.from;
      std::optional<State> end = branch.correct(next->x, next->p, zero_row, 1.0, end_p, o.newton.max_iterations, reason,
                                                result.newton_seconds);
      if (end) {
        if (branch.dot(end->tx, end->tp, next->tx, next->tp) < 0) end->tx = -end->tx, end->tp = -end->tp;
        s_b = branch.dot(current->tx, current->tp, end->x - current->x, end->p - current->p);
        next = std::move(end);
      }
      last = true;
      result.end = past_to >= 0 ? "to" : "from";
    }
    ContinuationPoint point;
    try {
      point = branch.evaluate(*next, result.krylov_seconds);
    } catch (const NumericalFailure& e) {
      result.end = "failure";
      result.failure = "multipliers at parameter " + format_number(next->p) + " (after point " +
                       std::to_string(result.points.size() - 1) + "): " + e.what();
      break;
    }
    point.step = ds;
    const ContinuationPoint& previous = result.points.back();
    if (o.locate && !(start_tangent && result.points.size() == 1)) {
      std::vector<BifurcationType> found =
          cd::detected_changes(cd::unstable_counts(previous.multipliers), cd::unstable_counts(point.multipliers));
      // A turning point of the parameter is a fold, located where dp/ds = 0 (for the discrete
      // problem exactly where F_x is singular: a multiplier +1, or at a corner of a piecewise-
      // smooth branch none); a multiplier through +1 without one (a branch point) by the multiplier.
      const bool turning = (previous.tangent_p > 0) != (point.tangent_p > 0);
      if (turning && std::find(found.begin(), found.end(), BifurcationType::fold) == found.end())
        found.push_back(BifurcationType::fold);
      if constexpr (Model::has_switching)
        if ((previous.measures.max_H > 0) != (point.measures.max_H > 0)) found.push_back(BifurcationType::grazing);
      const ContinuationPoint a = previous;
      for (BifurcationType type : found)
        locate(type, turning && type == BifurcationType::fold, *current, a, point, next->x, s_b,
               static_cast<long>(result.points.size()) - 1);
    }
    const int iterations = next->iterations;
    previous_state = std::move(current);
    current = std::move(next);
    add_point(std::move(point));
    if (last) break;
    if (iterations <= 3) ds = std::min(1.5 * ds, o.step_max);
    else if (iterations >= 6) ds = std::max(0.7 * ds, o.step_min);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - run_start).count();
  return result;
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
  const Map map1(TrapezoidStepper<Model>(model, so),
                 make_grid(model.tau(), model.period(), options.N, options.periods_per_map));
  const Map map2(TrapezoidStepper<Model>(model, so),
                 make_grid(model.tau(), model.period(), options.N, 2 * options.periods_per_map));
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
  return continuation_detail::trace_branch<Model>(model_at, x0, o2, &tangent, at.parameter);
}

}  // namespace delayspec
