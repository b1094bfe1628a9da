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
// (event handling: event_step.hpp). The derivative of (*) is
//
//   dz1 = S^{-1} [ (I + dt/2 A_l) dz0 + dt/2 B_l dw0 + dt/2 B_r dw1 ],   S = I - dt/2 A_r.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/LU>

#include "delayspec/detail/event_step.hpp"  // event_step(), called by step()
#include "delayspec/detail/small_solve.hpp"
#include "delayspec/detail/sub_step_derivative.hpp"
#include "delayspec/detail/time_switch_step.hpp"  // time_switch_step(), called by step()
#include "delayspec/errors.hpp"
#include "delayspec/model.hpp"
#include "delayspec/step_map.hpp"
#include "delayspec/step_options.hpp"

namespace delayspec {

// (t, y, y(t - tau)) as a NonFiniteStep reports it (errors.hpp).
// With several delays y_tau is their stack (model.hpp), DW rows.
template <int D, int DW = D>
ModelPoint model_point(double t, const Vec<D>& y, const Vec<DW>& y_tau) {
  return ModelPoint{t, std::vector<double>(y.data(), y.data() + D),
                    std::vector<double>(y_tau.data(), y_tau.data() + DW)};
}

template <class Model>
class TrapezoidStepper {
  static_assert(DelayModel<Model>, "Model does not satisfy the model contract (delayspec/model.hpp, DelayModel)");

 public:
  static constexpr int D = Model::d;
  static constexpr int DW = delayed_rows<Model>;  // D, or D n with n delays (model.hpp)
  using V = Vec<D>;
  using W = DelayedVec<Model>;  // the delayed argument
  using M = Mat<D>;

  // BadInput when options.contact_substeps < 1 or fixed_region is not 0, 1 or 2.
  explicit TrapezoidStepper(const Model& model, const StepOptions& options = {}) : model_(model), options_(options) {
    if (options.contact_substeps < 1)
      throw BadInput("`contact_substeps = " + std::to_string(options.contact_substeps) + "`: must be >= 1");
    if (options.fixed_region < 0 || options.fixed_region > 2)
      throw BadInput("TrapezoidStepper: fixed_region = " + std::to_string(options.fixed_region) +
                     " (0: the regions of the states, 1 or 2: that region's field)");
  }

  // One sub-step (*) from (t0, z0) over dt. left_region is used at the left node;
  // right_region at the right node (kRegionOfEndpoint: the region of z1 itself).
  // Throws NumericalFailure if the implicit equation cannot be solved. Always inlined, as the
  // solve inside it: for D <= 2 the whole step is ~100 flops, and a call returning the result
  // through memory cost the scalar Lyapunov step 4 of its 8 ns (bench_lyapunov).
  [[gnu::always_inline]] inline SubStepResult<D, DW> sub_step(double t0, double dt, const V& z0, const W& w0, const W& w1,
                                                          int left_region, int right_region) const {
    SubStepResult<D, DW> r;
    detail::SubStepDerivative<D, DW> derivative;
    r.z1 = factored_sub_step(t0, dt, z0, w0, w1, left_region, right_region, derivative, r.right_region);
    r.dz0 = derivative.dz0();
    r.dw0 = derivative.dw0();
    r.dw1 = derivative.dw1();
    return r;
  }

  // The same sub-step with its derivative in factored form (sub_step_derivative.hpp: S^{-1}
  // and the three right-hand matrices, no product formed); right_region_out receives the right
  // node's region. Returns z1.
  [[gnu::always_inline]] inline V factored_sub_step(double t0, double dt, const V& z0, const W& w0, const W& w1,
                                                    int left_region, int right_region,
                                                    detail::SubStepDerivative<D, DW>& derivative,
                                                    int& right_region_out) const {
    const double t1 = t0 + dt;
    const V z1 = solve_sub_step(t0, dt, z0, w0, w1, left_region, right_region, right_region_out, derivative.s);
    const int jr = right_region_out;
    // For an affine f the last Newton matrix is already S at z1 (A does not depend on z).
    if (!Model::affine_in_state) derivative.s.compute(M::Identity() - 0.5 * dt * model_.A(jr, t1, z1, w1));
    derivative.set_blocks(0.5 * dt, model_.A(left_region, t0, z0, w0), model_.B(left_region, t0, z0, w0),
                          model_.B(jr, t1, z1, w1));
    return z1;
  }

  // z1 of the same sub-step without its derivatives (event location evaluates many of these).
  V sub_step_state(double t0, double dt, const V& z0, const W& w0, const W& w1, int left_region,
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
  // Always inlined (a dispatch; the event and time-switch steps stay calls): see sub_step.
  [[gnu::always_inline]] inline V step(double t, double h, const V& u0, const W& w0, const W& w1, StepMap<D, DW>& map,
                                       StepEvents* events = nullptr) const {
    StepLinearisation<D, DW> linearisation;
    const V u1 = step(t, h, u0, w0, w1, linearisation, events);
    map = linearisation.formed();
    return u1;
  }

  // The same step with its derivative as a StepLinearisation (step_map.hpp): factored when the
  // step is one sub-step (no event or time switch inside it), for a caller that applies it once
  // to a few tangent vectors (the Lyapunov loop) and need not form P, Q, R.
  [[gnu::always_inline]] inline V step(double t, double h, const V& u0, const W& w0, const W& w1,
                                       StepLinearisation<D, DW>& linearisation, StepEvents* events = nullptr) const {
    if constexpr (Model::has_switching) {
      if (options_.fixed_region != 0) [[unlikely]]  // one field throughout (step_options.hpp)
        return fixed_region_step(t, h, u0, w0, w1, linearisation, events);
      if (options_.events != EventMode::off) return event_step(*this, t, h, u0, w0, w1, linearisation, events);
    }
    if (events) events->count = 0;
    if constexpr (TimeSwitchedModel<Model>) {
      // The switch times are known exactly: `on` and `linear` both split the step there.
      if (options_.events != EventMode::off) return detail::time_switch_step(*this, t, h, u0, w0, w1, linearisation);
    }
    return plain_step(t, h, u0, w0, w1, linearisation);
  }

  // The plain (unsplit) trapezoid step, whatever the options: each node in its own region (the
  // region of its state, or for time switches the branch in force at its time).
  [[gnu::always_inline]] inline V plain_step(double t, double h, const V& u0, const W& w0, const W& w1,
                                             StepMap<D, DW>& map) const {
    StepLinearisation<D, DW> linearisation;
    const V u1 = plain_step(t, h, u0, w0, w1, linearisation);
    map = linearisation.formed();
    return u1;
  }
  [[gnu::always_inline]] inline V plain_step(double t, double h, const V& u0, const W& w0, const W& w1,
                                             StepLinearisation<D, DW>& linearisation) const {
    int left = region_of(model_, u0), right = kRegionOfEndpoint;
    if constexpr (TimeSwitchedModel<Model>) left = model_.time_segment(t), right = model_.time_segment(t + h);
    int right_region;
    linearisation.factored = true;
    return factored_sub_step(t, h, u0, w0, w1, left, right, linearisation.sub, right_region);
  }

  const Model& model() const { return model_; }
  const StepOptions& options() const { return options_; }

  // The plain step with both nodes in `region` (a step of an aligned orbit's grid, inside one piece
  // between its contacts: HistoryGrid::step_region), its map formed.
  V region_step(double t, double h, const V& u0, const W& w0, const W& w1, int region, StepMap<D, DW>& map) const {
    StepLinearisation<D, DW> linearisation;
    int right_region;
    linearisation.factored = true;
    const V u1 = factored_sub_step(t, h, u0, w0, w1, region, region, linearisation.sub, right_region);
    map = linearisation.formed();
    return u1;
  }

  // The step in options().fixed_region's field alone. Not inlined into step(): a second inlined
  // sub-step there made every step of the impact model's Lyapunov loop 10% slower (farm-bench).
  [[gnu::noinline]] V fixed_region_step(double t, double h, const V& u0, const W& w0, const W& w1,
                                        StepLinearisation<D, DW>& linearisation, StepEvents* events) const {
    if (events) events->count = 0;
    int right_region;
    linearisation.factored = true;
    return factored_sub_step(t, h, u0, w0, w1, options_.fixed_region, options_.fixed_region, linearisation.sub,
                             right_region);
  }

 private:
  // Newton on G(z) = z - rhs0 - dt/2 f_jr(t1, z, w1). Returns z1; jr receives the right node's
  // region and lu the factorisation of S = I - dt/2 A_jr(t1, z, w1) at the last iterate.
  // Always inlined into its callers: GCC can then evaluate a model's sin/cos(t0) once for f and A
  // at the left node (-fno-math-errno); measured 6 % of a Mathieu Lyapunov run.
  //
  // kRecord (failures only: throw_non_finite_sub_step) also notes in *last_finite the last finite
  // iterate at which f and A were evaluated, and returns a state that is not finite instead of
  // throwing; the instantiation every step runs does neither.
  template <bool kRecord = false>
  [[gnu::always_inline]] inline V solve_sub_step(double t0, double dt, const V& z0, const W& w0, const W& w1,
                                                 int left_region, int right_region, int& jr,
                                                 detail::SmallSolve<D>& lu, V* last_finite = nullptr) const {
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
      if constexpr (kRecord)
        if (z.allFinite()) *last_finite = z;
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
    if (!z.allFinite()) {
      if constexpr (kRecord) return z;
      throw_non_finite_sub_step(t0, dt, z0, w0, w1, left_region, right_region, region_changes);
    }
    if (!converged)
      throw NumericalFailure("trapezoid step at t = " + format_number(t0) + ", dt = " + format_number(dt) +
                             ": implicit equation not solved (region changes " + std::to_string(region_changes) +
                             ", state " + format_number(z[0]) + ")");
    return z;
  }

  // A sub-step whose new state is not finite: NonFiniteStep with the points where it evaluated
  // the model, the left end and the last finite Newton iterate at the right end (where f or A is
  // not finite, when the model is: the caller may name the term). Newton is run again to find
  // that iterate, so that the steps that succeed keep nothing.
  [[gnu::noinline, gnu::cold]] void throw_non_finite_sub_step(double t0, double dt, const V& z0, const W& w0,
                                                             const W& w1, int left_region, int right_region,
                                                             int region_changes) const {
    V last_finite = z0;
    int jr = 0;
    detail::SmallSolve<D> lu;
    const V z = solve_sub_step<true>(t0, dt, z0, w0, w1, left_region, right_region, jr, lu, &last_finite);
    throw NonFiniteStep("trapezoid step at t = " + format_number(t0) + ", dt = " + format_number(dt) +
                            ": the new state is not finite (" + format_number(z[0]) + ", region changes " +
                            std::to_string(region_changes) + ")",
                        {model_point<D, DW>(t0, z0, w0), model_point<D, DW>(t0 + dt, last_finite, w1)});
  }

  Model model_;
  StepOptions options_;
};

}  // namespace delayspec
