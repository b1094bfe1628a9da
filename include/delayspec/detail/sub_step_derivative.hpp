#pragma once
// SubStepDerivative<D>: the derivative of one trapezoid sub-step (stepper.hpp, (*)), kept in the
// factored form in which the implicit function theorem gives it:
//
//   dz1 = S^{-1} [ L dz0 + Bl dw0 + Br dw1 ],
//   S = I - dt/2 A_r,  L = I + dt/2 A_l,  Bl = dt/2 B_l,  Br = dt/2 B_r,
//
// A = df/dz and B = df/dw at the left (l) and right (r) node. This file is the one statement of
// that formula: the blocks the step map stores (P = S^{-1} L, Q = S^{-1} Bl, R = S^{-1} Br) and
// its application to tangent vectors are both methods of this class.
//
// Why two forms. Forming P, Q, R costs 3 d^3 multiply-adds per step and applying them 3 d^2 k
// to k vectors; applying the factored form costs 4 d^2 k and forms nothing. A monodromy stores
// its step maps and applies them many times (form once); the Lyapunov loop applies each step's
// map once to its k (1-8) tangent vectors and forgets it (apply factored: at d = 2, k = 2, 32
// multiply-adds against 48). The two differ by rounding only (re-association of the same sums);
// tests/engine/test_sub_step_derivative.cpp ties them together.
#include <Eigen/Core>

#include "delayspec/detail/small_solve.hpp"
#include "delayspec/types.hpp"

namespace delayspec::detail {

// DW: the rows of the delayed argument (D, or D n for n delays: Bl and Br are D x DW).
template <int D, int DW = D>
struct SubStepDerivative {
  SmallSolve<D> s;        // S = I - dt/2 A_r, solved
  Mat<D> left;            // L  = I + dt/2 A_l
  RectMat<D, DW> bl;      // Bl = dt/2 B_l
  RectMat<D, DW> br;      // Br = dt/2 B_r

  // Fills L, Bl, Br from A_l, B_l, B_r (S is set by the caller, from its Newton solve).
  // Coefficient by coefficient, on purpose: the model has just built A and B with scalar stores
  // (Eigen's comma initializer), and GCC turns `c * B` into 16-byte loads of B's columns; a load
  // spanning two stores is not forwarded (AMD Zen: it waits for both to reach the cache), which
  // cost the impact model's Lyapunov step 10 ns (bench_lyapunov, perf annotate).
  [[gnu::always_inline]] inline void set_blocks(double half_dt, const Mat<D>& a_left,
                                                const RectMat<D, DW>& b_left, const RectMat<D, DW>& b_right) {
    for (int c = 0; c < D; ++c)
      for (int r = 0; r < D; ++r) {
        left(r, c) = (r == c ? 1.0 : 0.0) + half_dt * a_left(r, c);
        bl(r, c) = half_dt * b_left(r, c);
        br(r, c) = half_dt * b_right(r, c);
      }
    for (int c = D; c < DW; ++c)  // the other delays' columns (several delays only)
      for (int r = 0; r < D; ++r) {
        bl(r, c) = half_dt * b_left(r, c);
        br(r, c) = half_dt * b_right(r, c);
      }
  }

  // The blocks of the step map: dz1/dz0, dz1/dw0, dz1/dw1.
  Mat<D> dz0() const { return s.solve(left); }
  RectMat<D, DW> dw0() const { return s.solve(bl); }
  RectMat<D, DW> dw1() const { return s.solve(br); }

  // dZ1 = S^{-1} (L dZ0 + Bl dW0 + Br dW1) for D x c blocks of tangent vectors (c columns),
  // written row by row: row r of a block holds component r of the c vectors, so each term is a
  // scalar coefficient times a row (packed over the vectors: two per SSE2 register). Eigen's own
  // product of a column-major 2 x 2 by a row-major 2 x c block runs coefficient by coefficient
  // (its result is column-major), measured 3 ns per step slower at k = 2.
  template <class Z, class W0, class W1>
  [[gnu::always_inline]] inline auto apply(const Eigen::MatrixBase<Z>& dz0, const Eigen::MatrixBase<W0>& dw0,
                                           const Eigen::MatrixBase<W1>& dw1) const {
    constexpr int C = Z::ColsAtCompileTime;  // row-major like the tangent slots (a column: Eigen wants ColMajor)
    using Block = Eigen::Matrix<double, D, C, C == 1 ? Eigen::ColMajor : Eigen::RowMajor>;
    Block rhs;  // L dZ0 + Bl dW0 + Br dW1
    for (int r = 0; r < D; ++r) {
      rhs.row(r) = left(r, 0) * dz0.row(0) + bl(r, 0) * dw0.row(0) + br(r, 0) * dw1.row(0);
      for (int c = 1; c < D; ++c) rhs.row(r) += left(r, c) * dz0.row(c) + bl(r, c) * dw0.row(c) + br(r, c) * dw1.row(c);
      for (int c = D; c < DW; ++c) rhs.row(r) += bl(r, c) * dw0.row(c) + br(r, c) * dw1.row(c);  // other delays
    }
    if constexpr (requires { s.inverse(); }) {
      Block out;  // S^{-1} rhs through the stored inverse, row by row as above
      for (int r = 0; r < D; ++r) {
        out.row(r) = s.inverse()(r, 0) * rhs.row(0);
        for (int c = 1; c < D; ++c) out.row(r) += s.inverse()(r, c) * rhs.row(c);
      }
      return out;
    } else {
      return Block(s.solve(rhs));
    }
  }
};

}  // namespace delayspec::detail
