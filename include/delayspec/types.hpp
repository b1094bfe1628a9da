#pragma once
// The fixed-size vector and matrix types of a state of dimension D: what the model, the step
// map, the operator and the analyses share (the operator layer needs these, not the model).
#include <Eigen/Core>

namespace delayspec {

template <int D>
using Vec = Eigen::Matrix<double, D, 1>;
template <int D>
using Mat = Eigen::Matrix<double, D, D>;
// D rows, DW columns: the derivative of a field by the delayed values of a model with several
// delays (DW = D times their number; model.hpp).
template <int D, int DW>
using RectMat = Eigen::Matrix<double, D, DW>;

}  // namespace delayspec
