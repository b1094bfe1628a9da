#pragma once
// SmallSolve<D>: x = S^{-1} b for the d x d matrix S = I - dt/2 A of a trapezoid sub-step, with
// right-hand sides that are vectors or d x c matrices (the step map's blocks, tangents).
//
// Why not Eigen::PartialPivLU<Mat<D>>: its solve with a matrix right-hand side goes through
// Eigen's blocked triangular_solve_matrix (packing, dynamic loops) even for fixed D = 2; measured
// (perf, lyapunov of the Mathieu model, N = 1000) it took 32 % of the whole run. For D <= 4 the
// explicit inverse (Eigen's closed-form cofactor formula, ~ 10 flops at D = 2) is stored once and
// every solve is a fixed-size product that inlines. Accuracy: the forward error of x = S^{-1} b
// through the inverse is bounded by c cond(S) eps |x|, the same order as the LU solve's
// (S = I - dt/2 A is within O(dt |A|) of I in every use, so cond(S) is O(1) unless the step is
// far too coarse for the model); the tests compare against finite differences and dense
// references at 1e-8 ... 1e-12, far above this. Larger D keeps the LU factorisation.
#include <Eigen/Core>
#include <Eigen/LU>

namespace delayspec::detail {

template <int D, bool kUseInverse = (D <= 4)>
class SmallSolve;

template <int D>
class SmallSolve<D, true> {
 public:
  using M = Eigen::Matrix<double, D, D>;
  SmallSolve() = default;
  explicit SmallSolve(const M& s) { compute(s); }
  void compute(const M& s) { inverse_ = s.inverse(); }
  template <class B>
  auto solve(const Eigen::MatrixBase<B>& b) const {
    return (inverse_ * b).eval();  // x = S^{-1} b
  }
  const M& inverse() const { return inverse_; }  // S^{-1}

 private:
  M inverse_;
};

template <int D>
class SmallSolve<D, false> {
 public:
  using M = Eigen::Matrix<double, D, D>;
  SmallSolve() = default;
  explicit SmallSolve(const M& s) { compute(s); }
  void compute(const M& s) { lu_.compute(s); }
  template <class B>
  auto solve(const Eigen::MatrixBase<B>& b) const {
    return lu_.solve(b).eval();  // x = S^{-1} b, partial-pivoting LU
  }

 private:
  Eigen::PartialPivLU<M> lu_;
};

}  // namespace delayspec::detail
