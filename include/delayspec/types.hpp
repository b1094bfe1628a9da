#pragma once
// The fixed-size vector and matrix types of a state of dimension D: what the model, the step
// map, the operator and the analyses share (the operator layer needs these, not the model).
#include <Eigen/Core>

namespace delayspec {

template <int D>
using Vec = Eigen::Matrix<double, D, 1>;
template <int D>
using Mat = Eigen::Matrix<double, D, D>;

}  // namespace delayspec
