#pragma once
// The implicit trapezoidal ("modified Euler") step of design.md 1.2 and its step map (1.3).
//
// A full step from t to t + h advances the current state u_0 only; the history shift is the
// caller's business (it happens once per full step). The step receives the delayed values at
// its two ends, y_tau(t) and y_tau(t + h), and is built from sub-steps
//
//   z1 = z0 + dt/2 [ f_jl(t0, z0, w0) + f_jr(t0 + dt, z1, w1) ]          (*)
//
// so that an event (a crossing of H = 0) can split it into pieces with explicit regions
// (event handling: see the events extension). The derivative of (*) is
//
//   dz1 = S^{-1} [ (I + dt/2 A_l) dz0 + dt/2 B_l dw0 + dt/2 B_r dw1 ],   S = I - dt/2 A_r.
#include <array>
#include <cmath>
#include <string>

#include <Eigen/LU>

#include "delayspec/detail/small_solve.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/model.hpp"
#include "delayspec/step_map.hpp"

namespace delayspec {

// How a step treats a crossing of the switching surface H = 0 (design.md 1.5).
enum class EventMode { on, linear, off };
// Which derivative of a step with events: the exact derivative of the discrete map
// (event-time sensitivity included) or the paper's, with the split points frozen.
enum class JacobianMode { consistent, frozen };

struct StepOptions {
  EventMode events = EventMode::on;
  JacobianMode jacobian = JacobianMode::consistent;
  // Trapezoid sub-steps per piece of a step on the H > 0 side (contact), events on/linear only:
  // resolves a contact shorter than h (design.md 1.5). >= 1; 1 = one trapezoid per piece.
  // Default 4: a split step's trapezoid error depends on where the event falls in the step,
  // which adds an O(h^2) term to the multipliers whose constant jumps with N; m sub-steps shrink
  // it by m^2. On the paper's orbit m = 1 converges erratically (observed order -0.1 between
  // N = 1600 and 3200), m = 4 with order 1.95 (docs/events.md), at no measurable cost there.
  int contact_substeps = 4;
};

// What happened inside one step (filled by step() when asked; events off: always empty).
struct StepEvents {
  static constexpr int kMaxEvents = 16;  // more crossings than this in one step: NumericalFailure
  int count = 0;
  std::array<double, kMaxEvents> offset{};  // event time minus step start, in [0, h]
  std::array<int, kMaxEvents> new_region{};  // region entered at the event (1: H > 0, contact)
  // Number of entries into region 1 (impacts, for the impact model).
  int entries_into_region1() const {
    int n = 0;
    for (int i = 0; i < count; ++i) n += new_region[i] == 1;
    return n;
  }
};

template <class Model>
class TrapezoidStepper;
// One full step with event location (event_step.hpp); called by TrapezoidStepper::step().
template <class Model>
Vec<Model::d> event_step(const TrapezoidStepper<Model>& stepper, double t, double h, const Vec<Model::d>& u0,
                         const Vec<Model::d>& w0, const Vec<Model::d>& w1, StepMap<Model::d>& map,
                         StepEvents* events);

// Region choice for the right node of a sub-step: a fixed region, or "the region of z1"
// (found together with z1: the plain, unsplit trapezoid rule).
inline constexpr int kRegionOfEndpoint = 0;

template <int D>
struct SubStepResult {
  Vec<D> z1;
  Mat<D> dz0;  // dz1 / dz0
  Mat<D> dw0;  // dz1 / dw0 (delayed value at the left node)
  Mat<D> dw1;  // dz1 / dw1 (delayed value at the right node)
  int right_region = 1;
};

template <class Model>
class TrapezoidStepper {
 public:
  static constexpr int D = Model::d;
  using V = Vec<D>;
  using M = Mat<D>;

  // BadInput when options.contact_substeps < 1.
  explicit TrapezoidStepper(const Model& model, const StepOptions& options = {}) : model_(model), options_(options) {
    if (options.contact_substeps < 1)
      throw BadInput("`contact_substeps = " + std::to_string(options.contact_substeps) + "`: must be >= 1");
  }

  // One sub-step (*) from (t0, z0) over dt. left_region is used at the left node;
  // right_region at the right node (kRegionOfEndpoint: the region of z1 itself).
  // Throws NumericalFailure if the implicit equation cannot be solved.
  SubStepResult<D> sub_step(double t0, double dt, const V& z0, const V& w0, const V& w1, int left_region,
                            int right_region) const {
    const double t1 = t0 + dt;
    SubStepResult<D> r;
    detail::SmallSolve<D> lu;
    r.z1 = solve_sub_step(t0, dt, z0, w0, w1, left_region, right_region, r.right_region, lu);
    const int jr = r.right_region;
    // For an affine f the last Newton matrix is already S at z1 (A does not depend on z).
    if (!Model::affine_in_state) lu.compute(M::Identity() - 0.5 * dt * model_.A(jr, t1, r.z1, w1));
    r.dz0 = lu.solve(M::Identity() + 0.5 * dt * model_.A(left_region, t0, z0, w0));
    r.dw0 = lu.solve(0.5 * dt * model_.B(left_region, t0, z0, w0));
    r.dw1 = lu.solve(0.5 * dt * model_.B(jr, t1, r.z1, w1));
    return r;
  }

  // z1 of the same sub-step without its derivatives (event location evaluates many of these).
  V sub_step_state(double t0, double dt, const V& z0, const V& w0, const V& w1, int left_region,
                   int right_region) const {
    int jr;
    detail::SmallSolve<D> lu;
    return solve_sub_step(t0, dt, z0, w0, w1, left_region, right_region, jr, lu);
  }

  // One full step from t to t + h: returns u_0(t + h) and fills the step map (its exact
  // derivative wrt u0, w0 = y_tau(t), w1 = y_tau(t + h)). For a model with switching and
  // events on/linear the step is split at the events inside it (event_step.hpp) and `events`,
  // when given, receives them; otherwise (events off, or no switching) it is the plain
  // trapezoid, each node in the region of its own state.
  V step(double t, double h, const V& u0, const V& w0, const V& w1, StepMap<D>& map,
         StepEvents* events = nullptr) const {
    if constexpr (Model::has_switching) {
      if (options_.events != EventMode::off) return event_step(*this, t, h, u0, w0, w1, map, events);
    }
    if (events) events->count = 0;
    return plain_step(t, h, u0, w0, w1, map);
  }

  // The plain (unsplit) trapezoid step, whatever the options: each node in its own region.
  V plain_step(double t, double h, const V& u0, const V& w0, const V& w1, StepMap<D>& map) const {
    SubStepResult<D> s = sub_step(t, h, u0, w0, w1, region_of(model_, u0), kRegionOfEndpoint);
    map.P = s.dz0;
    map.Q = s.dw0;
    map.R = s.dw1;
    return s.z1;
  }

  const Model& model() const { return model_; }
  const StepOptions& options() const { return options_; }

 private:
  // Newton on G(z) = z - rhs0 - dt/2 f_jr(t1, z, w1). Returns z1; jr receives the right node's
  // region and lu the factorisation of S = I - dt/2 A_jr(t1, z, w1) at the last iterate.
  V solve_sub_step(double t0, double dt, const V& z0, const V& w0, const V& w1, int left_region, int right_region,
                   int& jr, detail::SmallSolve<D>& lu) const {
    const double t1 = t0 + dt;
    const V rhs0 = z0 + 0.5 * dt * model_.f(left_region, t0, z0, w0);  // explicit half
    // For an affine f_jr one Newton step is exact. In the automatic mode (the plain, unsplit
    // trapezoid) a second iteration confirms it and detects a region change of z1; with a
    // fixed right region there is nothing to confirm.
    const bool fixed_region = right_region != kRegionOfEndpoint;
    V z = z0;
    jr = fixed_region ? right_region : region_of(model_, z);
    constexpr int kMaxIterations = 30;
    bool converged = false;
    int region_changes = 0;
    for (int it = 0; it < kMaxIterations; ++it) {
      V g = z - rhs0 - 0.5 * dt * model_.f(jr, t1, z, w1);
      lu.compute(M(M::Identity() - 0.5 * dt * model_.A(jr, t1, z, w1)));
      V dz = lu.solve(g);
      z -= dz;
      const double scale = 1 + z.template lpNorm<Eigen::Infinity>();
      bool small = dz.template lpNorm<Eigen::Infinity>() <= 4 * 2.2e-16 * scale;
      if (!fixed_region) {
        int j_new = region_of(model_, z);
        if (j_new != jr) {
          jr = j_new;
          ++region_changes;
          if (region_changes > 8) break;  // cycling between regions: give up (reported below)
          continue;
        }
      }
      // Without switching the region cannot change: one iteration of an affine f is exact.
      if (small || (Model::affine_in_state && (fixed_region || it >= 1 || !Model::has_switching))) {
        converged = true;
        break;
      }
    }
    if (!converged || !z.allFinite())
      throw NumericalFailure("trapezoid step at t = " + format_number(t0) + ", dt = " + format_number(dt) +
                             ": implicit equation not solved (region changes " + std::to_string(region_changes) +
                             ", state " + format_number(z[0]) + ")");
    return z;
  }

  Model model_;
  StepOptions options_;
};

}  // namespace delayspec

#include "delayspec/event_step.hpp"  // IWYU pragma: export (event_step() used by step())
