#pragma once
// Finite-difference checks of the event step and the stroboscopic map (tests/test_events*.cpp).
#include <algorithm>
#include <cmath>
#include <vector>

#include "delayspec/model_impact.hpp"
#include "delayspec/orbit_simulation.hpp"
#include "delayspec/detail/scalar_search.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec::testing {

using V2 = Vec<2>;
using StepJacobian = Eigen::Matrix<double, 2, 6>;  // [P Q R]: d u0(t+h) / d(u0, w0, w1)

struct StepInput {
  double t = 0, h = 0;
  V2 u0, w0, w1;
};

inline StepJacobian as_matrix(const StepMap<2>& m) {
  StepJacobian J;
  J << m.P, m.Q, m.R;
  return J;
}

template <class Stepper>
V2 step_value(const Stepper& stepper, const StepInput& in, StepEvents* events = nullptr) {
  StepMap<2> scratch;
  return stepper.step(in.t, in.h, in.u0, in.w0, in.w1, scratch, events);
}

inline double& input_component(StepInput& in, int c) {
  V2& block = c < 2 ? in.u0 : c < 4 ? in.w0 : in.w1;
  return block[c % 2];
}

// Central differences of the step's result wrt its 6 inputs, step delta.
template <class Stepper>
StepJacobian central_differences(const Stepper& stepper, const StepInput& in, double delta) {
  StepJacobian F;
  for (int c = 0; c < 6; ++c) {
    StepInput p = in, m = in;
    input_component(p, c) += delta;
    input_component(m, c) -= delta;
    F.col(c) = (step_value(stepper, p) - step_value(stepper, m)) / (2 * delta);
  }
  return F;
}

// One-sided second-order differences (-3 f(0) + 4 f(s d) - f(2 s d)) / (2 s d), with the sign
// s = sides[c] (+1 or -1) per input: for points where the step is only one-sided differentiable.
template <class Stepper>
StepJacobian one_sided_differences(const Stepper& stepper, const StepInput& in, double delta, const int (&sides)[6]) {
  StepJacobian F;
  const V2 y0 = step_value(stepper, in);
  for (int c = 0; c < 6; ++c) {
    const double d = sides[c] * delta;
    StepInput p1 = in, p2 = in;
    input_component(p1, c) += d;
    input_component(p2, c) += 2 * d;
    F.col(c) = (-3 * y0 + 4 * step_value(stepper, p1) - step_value(stepper, p2)) / (2 * d);
  }
  return F;
}

template <class Stepper>
StepJacobian step_jacobian(const Stepper& stepper, const StepInput& in, StepEvents* events = nullptr) {
  StepMap<2> map;
  stepper.step(in.t, in.h, in.u0, in.w0, in.w1, map, events);
  return as_matrix(map);
}

inline double relative_error(const StepJacobian& approx, const StepJacobian& exact) {
  return (approx - exact).lpNorm<Eigen::Infinity>() / exact.lpNorm<Eigen::Infinity>();
}

// Paper parameters with tau = T and the history started near the period-1 orbit (the linear
// response), as in data/scenes/default.toml.
inline ImpactParameters paper_orbit_parameters(double k = 1.0) {
  ImpactParameters p;
  p.k = k;
  p.x0 = -0.0566;
  p.v0 = 1.0101;
  return p;
}

// The inputs of every step of one period of map from history U (aligned delay).
template <class Map>
std::vector<StepInput> step_inputs(const Map& map, const Eigen::VectorXd& U) {
  const HistoryGrid& g = map.grid();
  std::vector<V2> traj;
  map.apply(U, nullptr, &traj);
  std::vector<V2> b(static_cast<size_t>(g.M + 1 + g.K));
  for (long j = 0; j <= g.M; ++j) b[j] = U.segment<2>(2 * j);
  for (long l = 0; l < g.K; ++l) b[g.M + l + 1] = traj[l + 1];
  std::vector<StepInput> inputs;
  for (long l = 0; l < g.K; ++l) {
    const long j = g.M + l - g.m;
    inputs.push_back({static_cast<double>(l) * g.h, g.h, b[g.M + l], b[j], b[j + 1]});
  }
  return inputs;
}

}  // namespace delayspec::testing

namespace delayspec::testing {

// A step of length h from a state of the paper's orbit just before its contact (N = 100, step
// 24, literal data), with the obstacle e moved so that the free-flight (region 2) discrete
// sub-step z(s) of the step reaches exactly `penetration` beyond it at its highest point
// (region 2 does not depend on e, so the penetration is set exactly up to rounding of e).
// h = 0.25 holds the whole contact (~0.06 time units) inside one step: a grazing step.
struct GrazingCase {
  ImpactParameters parameters;
  StepInput input;
  double s_max = 0;  // offset of the highest point of the free-flight sub-step
};

inline GrazingCase grazing_case(double penetration, double h = 0.25, double beta = 28) {
  GrazingCase g;
  g.parameters = paper_orbit_parameters();
  g.parameters.beta = beta;
  g.input = {1.8802549547669585, h, V2(1.2538623987816964, 0.10961567106070286),
             V2(1.2538623986659863, 0.10961567102965634), V2(1.2550, -0.095)};
  const ImpactModel free_model(g.parameters);
  const TrapezoidStepper<ImpactModel> stepper(free_model);
  const StepInput& in = g.input;
  auto minus_x = [&](double s) {
    const V2 ws = (1 - s / h) * in.w0 + (s / h) * in.w1;
    return -stepper.sub_step(in.t, s, in.u0, in.w0, ws, 2, 2).z1[0];
  };
  const ScalarSearchResult top = bounded_minimum(minus_x, 0, h);
  g.s_max = top.x;
  g.parameters.e = -top.g - penetration;
  return g;
}

}  // namespace delayspec::testing
