#pragma once
// StepMap: the linearisation of one full time step (design.md 1.3). A step shifts the history
// by one block and computes one new block:
//
//   du_0(t + h) = P du_0(t) + Q dy_tau(t) + R dy_tau(t + h)
//
// where y_tau(t) = (1 - theta) u_m + theta u_{m+1} and y_tau(t + h) = (1 - theta) u_{m-1} +
// theta u_m are the delayed values at the step's two ends (grid.hpp). For an aligned delay
// (theta = 0) this is the design's P du_0 + Q du_N + R du_{N-1}. Steps containing events have
// the same form with other blocks.
#include "delayspec/types.hpp"

namespace delayspec {

template <int D>
struct StepMap {
  Mat<D> P = Mat<D>::Zero();
  Mat<D> Q = Mat<D>::Zero();
  Mat<D> R = Mat<D>::Zero();
};

}  // namespace delayspec
