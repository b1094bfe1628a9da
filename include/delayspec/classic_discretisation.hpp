#pragma once
// The classic dense discretisations of milling stability, as reference paths for `bench`
// (solvers sdm0, fdm1): each forms the monodromy of its own discrete map as a dense product of m
// step matrices and takes all its eigenvalues, as their authors do. For a linear T-periodic DDE
//
//   x' = A(t) x + B(t) x(t - tau),   tau = T = m dt,   t_i = i dt,
//
// with the delayed components y = C x (the columns of B that are not zero; milling: x only),
// both advance  Z_i = (x_i, y_{i-1}, ..., y_{i-m})  by
//
//   x_{i+1} = S_i x_i + D^a_i y_{i-m+1} + D^b_i y_{i-m},   y_i = C x_i,   the rest shifted:
//
// * sdm0, zeroth-order semi-discretisation (Insperger & Stepan, Int. J. Numer. Meth. Eng. 55,
//   2002; the milling code of their 2004 papers): on [t_i, t_{i+1}] the coefficients are their
//   averages A_i, B_i (midpoint rule with 40 points, as their codes sample h(t)) and the delayed
//   term the constant (y_{i-m+1} + y_{i-m}) / 2; the ODE is then solved exactly:
//   S_i = e^{A_i dt}, D^a_i = D^b_i = (1/2) int_0^dt e^{A_i s} ds B_i C^T.
// * fdm1, first-order full discretisation (Ding, Zhu, Zhang, Ding, Int. J. Mach. Tools Manuf. 50,
//   2010): A = A_0 + A_p(t) with A_0 constant; on [t_i, t_{i+1}], sigma = (t - t_i)/dt, the state
//   x, the delayed state, A_p and B are linear interpolants of their node values, and variation of
//   constants with K_p = int_0^dt e^{A_0 (dt - s)} (s/dt)^p ds (exact, by one exponential of a
//   block matrix: Van Loan, IEEE TAC 23, 1978) gives
//     (I - K_1 A_i - K_2 dA) x_{i+1} = (e^{A_0 dt} + (K_0 - K_1) A_i + (K_1 - K_2) dA) x_i
//                                      + (K_1 B_i + K_2 dB) x_{i-m+1} + ((K_0 - K_1) B_i + (K_1 - K_2) dB) x_{i-m},
//   A_i = A_p(t_i), dA = A_p(t_{i+1}) - A_p(t_i), likewise B. The coefficients are sampled at the
//   nodes (where a cutting window opens inside a step, nothing locates it). A_0 here is the
//   period mean of A(t) (milling: the structure plus the mean cutting stiffness); Ding et al.
//   take the structure alone. The choice only moves what the interpolation has to capture; the
//   mean leaves the smaller remainder, which favours fdm1.
//
// The product exploits the shift structure (O(n^2) per step, O(m^3) in all, n = d + m r); the
// published codes multiply full matrices (O(m^4)), so the times reported here favour them.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <unsupported/Eigen/MatrixFunctions>

#include "delayspec/classic_result.hpp"
#include "delayspec/dense_spectrum.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/model.hpp"
#include "delayspec/multipliers.hpp"

namespace delayspec {

namespace detail {

// The branch of a model's field in force at t (time switches), 1 for a model without them.
template <class Model>
int branch_at(const Model& model, double t) {
  if constexpr (TimeSwitchedModel<Model>) return model.time_segment(t);
  else return 1;
}

// e^X after diagonal balancing, e^X = S e^{S^-1 X S} S^-1 (Parlett & Reinsch's powers of two,
// as LAPACK's dgebal). Milling in SI units has |X| ~ 5e3 with eigenvalues of size 1 (omega_n^2
// dt next to dt): unbalanced, scaling and squaring loses 9 digits of the phase (measured: 7.6e-9
// rad on the free oscillator); balanced, the exponential is accurate to rounding.
inline Eigen::MatrixXd balanced_exponential(Eigen::MatrixXd X) {
  const long n = X.rows();
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(n);
  // A sweep rescales row and column i by a power of two f when that shrinks their norms by 5 %
  // (LAPACK's rule: without the threshold the sweeps can cycle).
  for (int sweep = 0, changed = 1; changed && sweep < 100; ++sweep) {
    changed = 0;
    for (long i = 0; i < n; ++i) {
      const double column = X.col(i).norm() - std::abs(X(i, i)), row = X.row(i).norm() - std::abs(X(i, i));
      if (!(column > 0 && row > 0)) continue;
      const double f = std::exp2(std::round(0.5 * std::log2(row / column)));
      if (!(column * f + row / f < 0.95 * (column + row))) continue;
      X.col(i) *= f;
      X.row(i) /= f;
      scale[i] *= f;
      changed = 1;
    }
  }
  Eigen::MatrixXd E = X.exp();
  return scale.asDiagonal() * E * scale.cwiseInverse().asDiagonal();
}

// exp of the block matrix [[A dt, I dt, 0, ..], [0, 0, I dt, ..], ...] with `levels` blocks:
// block (0, p) = int_0^dt e^{A (dt - s)} s^{p-1} / (p-1)! ds (Van Loan 1978).
template <int D>
Eigen::MatrixXd van_loan_exponential(const Mat<D>& A, double dt, int levels) {
  Eigen::MatrixXd big = Eigen::MatrixXd::Zero(D * levels, D * levels);
  big.topLeftCorner(D, D) = A * dt;
  for (int p = 1; p < levels; ++p) big.block((p - 1) * D, p * D, D, D).setIdentity() *= dt;
  return balanced_exponential(big);
}

}  // namespace detail

// The dense monodromy of the classic discretisation with m steps per period. BadInput when the
// model is not linear, has several delays, tau != T, or m < 2.
template <class Model>
Eigen::MatrixXd classic_monodromy(const Model& model, int m, ClassicMethod method) {
  constexpr int D = Model::d;
  using M = Mat<D>;
  using V = Vec<D>;
  if constexpr (!Model::is_linear) {
    throw BadInput("the classic discretisations (sdm0, fdm1) need a linear model");
  } else if constexpr (delay_count_of<Model>() > 1) {
    throw BadInput("the classic discretisations (sdm0, fdm1) take one delay (this model has " +
                   std::to_string(delay_count_of<Model>()) + ")");
  } else {
    const double T = model.period();
    if (std::abs(model.tau() - T) > 1e-12 * T)
      throw BadInput("the classic discretisations (sdm0, fdm1) need tau = T (tau = " + format_number(model.tau()) +
                     ", T = " + format_number(T) + ")");
    if (m < 2) throw BadInput("`N = " + std::to_string(m) + "`: the classic discretisations need N >= 2");
    const double dt = T / m;
    const V zero = V::Zero();
    auto A_at = [&](int j, double t) { return M(model.A(j, t, zero, zero)); };
    auto B_at = [&](int j, double t) { return M(model.B(j, t, zero, zero)); };
    // Coefficient means over step i (midpoint rule, 40 points per step, each in its own branch).
    constexpr int kPoints = 40;
    std::vector<M> A_mean(m, M::Zero()), B_mean(m, M::Zero());
    for (int i = 0; i < m; ++i)
      for (int q = 0; q < kPoints; ++q) {
        const double t = (i + (q + 0.5) / kPoints) * dt;
        const int j = detail::branch_at(model, t);
        A_mean[i] += A_at(j, t) / kPoints;
        B_mean[i] += B_at(j, t) / kPoints;
      }
    // The delayed components: columns of B that are non-zero at some sample (C selects them).
    std::vector<int> delayed;
    for (int c = 0; c < D; ++c) {
      bool used = false;
      for (int i = 0; i < m && !used; ++i) {
        const double t = i * dt;
        used = B_mean[i].col(c).cwiseAbs().maxCoeff() > 0 ||
               B_at(detail::branch_at(model, t), t).col(c).cwiseAbs().maxCoeff() > 0;
      }
      if (used) delayed.push_back(c);
    }
    const int r = static_cast<int>(delayed.size());
    const long n = D + static_cast<long>(m) * r;
    auto restrict_columns = [&](const M& full) {  // full C^T: the columns acting on y
      Eigen::MatrixXd out(D, r);
      for (int k = 0; k < r; ++k) out.col(k) = full.col(delayed[k]);
      return out;
    };
    M A0 = M::Zero();
    if (method == ClassicMethod::fdm1)
      for (int i = 0; i < m; ++i) A0 += A_mean[i] / m;
    Eigen::MatrixXd K;  // fdm1: the four-level exponential of A0, the same for every step
    if (method == ClassicMethod::fdm1) K = detail::van_loan_exponential<D>(A0, dt, 4);

    Eigen::MatrixXd Phi = Eigen::MatrixXd::Identity(n, n), next(n, n);
    for (int i = 0; i < m; ++i) {
      M S;
      Eigen::MatrixXd Da, Db;
      if (method == ClassicMethod::sdm0) {
        const Eigen::MatrixXd E = detail::van_loan_exponential<D>(A_mean[i], dt, 2);
        S = E.topLeftCorner(D, D);
        const Eigen::MatrixXd R = restrict_columns(M(E.block(0, D, D, D) * B_mean[i]));
        Da = 0.5 * R;
        Db = 0.5 * R;
      } else {
        const double t0 = i * dt, t1 = (i + 1) * dt;
        const int j0 = detail::branch_at(model, t0), j1 = detail::branch_at(model, t1);
        const M Ai = A_at(j0, t0) - A0, dA = A_at(j1, t1) - A0 - Ai;
        const M Bi = B_at(j0, t0), dB = B_at(j1, t1) - Bi;
        const M Phi0 = K.topLeftCorner(D, D), K0 = K.block(0, D, D, D), K1 = K.block(0, 2 * D, D, D) / dt,
                K2 = K.block(0, 3 * D, D, D) * (2 / (dt * dt));
        const Eigen::PartialPivLU<M> lhs(M(M::Identity() - K1 * Ai - K2 * dA));
        S = lhs.solve(M(Phi0 + (K0 - K1) * Ai + (K1 - K2) * dA));
        if (r > 0) {  // (Eigen's triangular solve is undefined on a matrix with no columns)
          Da = lhs.solve(restrict_columns(M(K1 * Bi + K2 * dB)));
          Db = lhs.solve(restrict_columns(M((K0 - K1) * Bi + (K1 - K2) * dB)));
        }
      }
      // Z_{i+1} = G_i Z_i applied to the rows of Phi: x from x, y_{i-m+1} (block m - 1) and
      // y_{i-m} (block m); y_i = C x_i; blocks 1 .. m-1 move down by one. Without delayed
      // components (r = 0, B = 0) Z = x and the step is S alone.
      const auto x_rows = Phi.topRows(D);
      if (r == 0) {
        next.topRows(D) = S * x_rows;
        Phi.swap(next);
        continue;
      }
      next.topRows(D) = S * x_rows + Da * Phi.middleRows(D + (m - 2) * r, r) + Db * Phi.middleRows(D + (m - 1) * r, r);
      for (int k = 0; k < r; ++k) next.row(D + k) = x_rows.row(delayed[k]);
      next.middleRows(D + r, (m - 1) * r) = Phi.middleRows(D, (m - 1) * r);
      Phi.swap(next);
    }
    return Phi;
  }
}

// The nev largest multipliers of the classic discretisation, with the time it took.
template <class Model>
ClassicResult classic_multipliers(const Model& model, int m, ClassicMethod method, int nev) {
  const auto start = std::chrono::steady_clock::now();
  const Eigen::MatrixXd Phi = classic_monodromy(model, m, method);
  std::vector<std::complex<double>> all = dense_eigenvalues(Phi, DenseBackend::lapack);
  ClassicResult result;
  result.dimension = Phi.rows();
  all.resize(std::min<size_t>(all.size(), static_cast<size_t>(std::max(nev, 1))));
  result.multipliers = all;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace delayspec
