#pragma once
// StepMap: the linearisation of one full time step (design.md 1.3). A step shifts the history
// by one block and computes one new block:
//
//   du_0(t + h) = P du_0(t) + Q dy_tau(t) + R dy_tau(t + h)
//
// where y_tau(t) = (1 - theta) u_m + theta u_{m+1} and y_tau(t + h) = (1 - theta) u_{m-1} +
// theta u_m are the delayed values at the step's two ends (grid.hpp). For an aligned delay
// (theta = 0) this is the design's P du_0 + Q du_N + R du_{N-1}. Steps containing events have
// the same form with other blocks. A model with several delays (model.hpp) has DW = D n
// delayed rows: Q and R are D x DW, one D x D block per delay, each applied to that delay's tap.
#include "delayspec/detail/sub_step_derivative.hpp"
#include "delayspec/types.hpp"

namespace delayspec {

template <int D, int DW = D>
struct StepMap {
  Mat<D> P = Mat<D>::Zero();
  RectMat<D, DW> Q = RectMat<D, DW>::Zero();
  RectMat<D, DW> R = RectMat<D, DW>::Zero();
};

// The derivative of one step as a step reports it (TrapezoidStepper::step): a step that is one
// trapezoid sub-step (no event or time switch inside it: most steps) keeps its derivative
// factored, S^{-1} [L du_0 + Bl dw0 + Br dw1] (detail/sub_step_derivative.hpp), and a caller
// that applies it once to a few vectors (the Lyapunov loop: apply_step_linearisation in
// block_kernel.hpp) never forms P, Q, R; a step split into pieces composes their maps into
// `map`. formed() is the StepMap either way (what a monodromy stores).
template <int D, int DW = D>
struct StepLinearisation {
  bool factored = false;                 // which of the two below holds the derivative
  detail::SubStepDerivative<D, DW> sub;  // factored: the step's one sub-step
  StepMap<D, DW> map;                    // otherwise: P, Q, R of the composed pieces

  StepMap<D, DW> formed() const {
    if (!factored) return map;
    return StepMap<D, DW>{sub.dz0(), sub.dw0(), sub.dw1()};
  }
};

}  // namespace delayspec
