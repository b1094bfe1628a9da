// TangentQR (detail/tangent_qr.hpp): Householder QR of the n x k row-major tangent block in
// k + 1 sweeps over its rows.
//
// The algorithm is LAPACK's (dgeqr2 + dlarft + the product of dorgqr/dlarfb), re-associated so
// that every reflector costs one pass. Notation: x_c is column c of the block as updated so far,
// H_j = I - tau_j v_j v_j^T with v_j zero above row j and v_j(j) = 1.
//
//  Sweep j (j = 0..k-1) applies H_{j-1} to the columns c >= j (rows >= j) and accumulates, on
//  the updated values, in the same pass
//      G_c  = sum_{r >= j} x_j(r) x_c(r)        (c >= j)
//      D_ij = sum_{r >  j} x_i(r) x_j(r)        (i < j; for v_i^T v_j below)
//  (sweep 0 also |x_c|^2 of every column: the norms of the dependence test and of the scaling
//  check). Then, with alpha_j = x_j(j),
//      beta_j = -sign(alpha_j) sqrt(G_j) = R_jj,      s_j = 1 / (alpha_j - beta_j),
//      tau_j = (beta_j - alpha_j) / beta_j,          v_j = s_j (x_j(j:) - beta_j e_j),
//      v_j^T x_c = s_j (G_c - beta_j x_c(j)),        w_c = tau_j v_j^T x_c            (c > j),
//  R_jc = x_c(j) - w_c, and the next sweep does x_c(r) -= (w_c s_j) x_j(r) for r > j. v_j is
//  never formed: column j keeps the unscaled x_j below the diagonal and s_j is folded into the
//  coefficients (no scaling pass, no pass for the norm, one pass per reflector application
//  instead of two).
//
// Stability (Higham, Accuracy and Stability of Numerical Algorithms, 2nd ed., 19.3): Householder
// QR is backward stable, Q R = A + dA with |dA_c| <= gamma(c n k) |a_c| and |Q^T Q - I| <=
// gamma(c n k), gamma(m) = m eps / (1 - m eps), for every A, whatever its condition number (the
// bounds Gram-Schmidt and Cholesky QR do not have: CGS2 needs cond(A) eps << 1, Cholesky QR
// cond(A)^2 eps << 1, and both lose orthogonality where the tangent vectors nearly align, which
// is where the exponents' last digits are decided). The re-association keeps the two
// ingredients of that proof: (1) each applied reflector is exactly orthogonal for the vector it
// uses (here v_j = s_j x_j exactly, the rounding moved into the coefficient w_c s_j, a relative
// perturbation of one multiplier), (2) v_j^T x_c is computed to within gamma(n) |v_j| |x_c|:
// G_c - beta_j x_c(j) has error <= gamma(n + 1) (|x_j| |x_c| + |beta_j x_c(j)|) <=
// 2 gamma(n + 1) |x_j| |x_c|, and |v_j| / |s_j| = |x_j - beta_j e_j| >= |x_j| (alpha_j beta_j <= 0).
//
//  Sweep k forms Q = H_0 ... H_{k-1} [I_k; 0] from the compact WY form (Schreiber and Van Loan
//  1989; dlarft) H_0 ... H_{k-1} = I - V T V^T, T upper triangular with T_jj = tau_j and
//      T(0:j, j) = -tau_j T(0:j, 0:j) (v_i^T v_j)_{i < j},   v_i^T v_j = s_i x_i(j) + s_i s_j D_ij,
//  so that Q = [I_k; 0] - V S with S = T V_top^T (V_top: rows 0..k-1 of V, unit lower
//  triangular): row r >= k of Q is sum_i x_i(r) W_ic with W = -diag(s) S diag(sign R_cc) (the
//  sign makes R_cc > 0), rows r < k come from the k x k top. The product by the k x k W is the
//  dlarfb product; I - V T V^T is orthogonal to the same gamma(c n k).
//
// Cost per row: sweep 0 reads the row (2k multiply-adds), sweep j updates k - j entries
// (2 (k - j) + j multiply-adds), sweep k writes a row of Q (k^2). For k = 2: three passes over
// the block (read; read and write column 1; read and write Q) against about 13 in the textbook
// order (the previous kernel: 3.4x slower at n = 2002, docs/benchmarks.md). Rows go two at a
// time through independent accumulators (the reductions' add latency). Compile-time k (and j)
// for k <= 8, runtime k up to kMaxTangentVectors otherwise.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "delayspec/lyapunov.hpp"

namespace delayspec {

namespace {

// Below n eps |a_c| the part of column c orthogonal to the previous ones is within the backward
// error of the factorisation (above): R_cc carries no digits, the vector is dependent.
double dependence_threshold(long n) { return static_cast<double>(n) * 2.220446049250313e-16; }

// The block's entries stay where squares neither overflow nor underflow when every column norm
// squared is in [2^-600, 2^600] (each entry is at most its column's norm, and the largest is at
// least the largest norm / sqrt(n)).
constexpr double kSquaresHigh = 0x1p600, kSquaresLow = 0x1p-600;

// Per-call scalars of the factorisation, in TangentQR's buffers (sized at construction).
struct Reflectors {
  double* tau;    // tau_j
  double* s;      // s_j = 1 / (alpha_j - beta_j) (0 when H_j = I)
  double* r;      // R_jj = beta_j
  double* sq;     // |a_c|^2 of the columns as given (sweep 0)
  double* coeff;  // w_c s_j: the pending reflector's multiplier of x_j for column c
  double* gram;   // G_c of the current sweep
  double* vdot;   // D_ij, k x k row-major (i < j)
  double* t;      // T, k x k row-major
  double* w;      // W, k x k row-major
  double* q_top;  // rows 0..k-1 of Q, k x k row-major
};

template <int KC>
constexpr int capacity() {
  return KC > 0 ? KC : kMaxTangentVectors;
}

// Sweep 0 (rows 0..n-1): G_c = x_0 . x_c and |x_c|^2 for every column.
template <int KC>
void first_sweep(const double* a, long n, int k_runtime, Reflectors& f) {
  const int k = KC > 0 ? KC : k_runtime;
  double g0[capacity<KC>()], g1[capacity<KC>()], q0[capacity<KC>()], q1[capacity<KC>()];
  for (int c = 0; c < k; ++c) g0[c] = g1[c] = q0[c] = q1[c] = 0;
  long r = 0;
  for (; r + 1 < n; r += 2) {  // two rows in flight
    const double* x = a + r * k;
    const double* y = x + k;
    for (int c = 0; c < k; ++c) {
      g0[c] += x[0] * x[c];
      g1[c] += y[0] * y[c];
      q0[c] += x[c] * x[c];
      q1[c] += y[c] * y[c];
    }
  }
  if (r < n)
    for (int c = 0; c < k; ++c) {
      g0[c] += a[r * k] * a[r * k + c];
      q0[c] += a[r * k + c] * a[r * k + c];
    }
  for (int c = 0; c < k; ++c) {
    f.gram[c] = g0[c] + g1[c];
    f.sq[c] = q0[c] + q1[c];
  }
}

// Sweep j >= 1 (rows j..n-1): x_c -= coeff_c x_{j-1} for c >= j, then G_c (c >= j) and D_ij
// (i < j) on the updated values. JC: j at compile time (KC > 0), else -1 and j_runtime.
template <int KC, int JC>
void sweep(double* a, long n, int k_runtime, int j_runtime, Reflectors& f) {
  const int k = KC > 0 ? KC : k_runtime;
  const int j = JC >= 0 ? JC : j_runtime;
  double coeff[capacity<KC>()], g0[capacity<KC>()], g1[capacity<KC>()], d0[capacity<KC>()], d1[capacity<KC>()];
  for (int c = j; c < k; ++c) coeff[c] = f.coeff[c];
  {  // row j: its head; D_ij starts below it
    double* x = a + j * k;
    for (int c = j; c < k; ++c) x[c] -= coeff[c] * x[j - 1];
    for (int c = j; c < k; ++c) {
      g0[c] = x[j] * x[c];
      g1[c] = 0;
    }
    for (int i = 0; i < j; ++i) d0[i] = d1[i] = 0;
  }
  long r = j + 1;
  for (; r + 1 < n; r += 2) {  // two rows in flight
    double* x = a + r * k;
    double* y = x + k;
    for (int c = j; c < k; ++c) {
      x[c] -= coeff[c] * x[j - 1];
      y[c] -= coeff[c] * y[j - 1];
    }
    for (int c = j; c < k; ++c) {
      g0[c] += x[j] * x[c];
      g1[c] += y[j] * y[c];
    }
    for (int i = 0; i < j; ++i) {
      d0[i] += x[i] * x[j];
      d1[i] += y[i] * y[j];
    }
  }
  if (r < n) {
    double* x = a + r * k;
    for (int c = j; c < k; ++c) x[c] -= coeff[c] * x[j - 1];
    for (int c = j; c < k; ++c) g0[c] += x[j] * x[c];
    for (int i = 0; i < j; ++i) d0[i] += x[i] * x[j];
  }
  for (int c = j; c < k; ++c) f.gram[c] = g0[c] + g1[c];
  for (int i = 0; i < j; ++i) f.vdot[i * k + j] = d0[i] + d1[i];
}

// Reflector j from the sweep's G (rows >= j): beta_j, s_j, tau_j; R_jc for c > j and the
// multipliers of the next sweep.
void make_reflector(double* a, int k, int j, Reflectors& f) {
  double* head = a + j * k;  // row j
  const double alpha = head[j], norm = std::sqrt(f.gram[j]);
  const double beta = -std::copysign(norm, alpha);
  const bool identity = norm == 0;  // a zero column (reported as dependent): H_j = I
  f.s[j] = identity ? 0 : 1 / (alpha - beta);
  f.tau[j] = identity ? 0 : (beta - alpha) / beta;
  f.r[j] = identity ? alpha : beta;
  head[j] = f.r[j];
  for (int c = j + 1; c < k; ++c) {
    const double w = f.tau[j] * (f.gram[c] - beta * head[c]) * f.s[j];  // tau_j v_j^T x_c
    head[c] -= w;                                                       // R_jc
    f.coeff[c] = w * f.s[j];
  }
}

// W = -diag(s) T V_top^T diag(sign R_cc) and rows 0..k-1 of Q (header comment), through T
// (dlarft, forward columnwise). O(k^3) on k x k matrices; V_top(r, m) = s_m x_m(r) below its unit
// diagonal. Rows r < k of Q, sign_c (delta_rc - S(r, c)) + sum_{i < r} x_i(r) W_ic, go to q_top
// (Q may overwrite the block, TangentQR::factorise, whose rows 0..k-1 are still read here).
void make_q_coefficients(const double* a, int k, Reflectors& f) {
  double* t = f.t;
  for (int j = 0; j < k; ++j) {
    for (int i = 0; i < j; ++i) {  // z_i = v_i^T v_j, kept in T(i, j) until multiplied by T(0:j, 0:j)
      t[i * k + j] = f.s[i] * a[j * k + i] + f.s[i] * f.s[j] * f.vdot[i * k + j];
      t[j * k + i] = 0;
    }
    for (int i = 0; i < j; ++i) {  // T(i, j) = -tau_j sum_{m >= i} T(i, m) z_m (row i still sees z_m, m >= i)
      double sum = 0;
      for (int m = i; m < j; ++m) sum += t[i * k + m] * t[m * k + j];
      t[i * k + j] = -f.tau[j] * sum;
    }
    t[j * k + j] = f.tau[j];
  }
  for (int r = 0; r < k; ++r)
    for (int c = 0; c < k; ++c) {  // S(r, c) = T(r, c) + sum_{m = r}^{c - 1} T(r, m) s_m x_m(c)
      double s_rc = c >= r ? t[r * k + c] : 0;
      for (int m = r; m < c; ++m) s_rc += t[r * k + m] * f.s[m] * a[c * k + m];
      const double sign = f.r[c] < 0 ? -1 : 1;
      f.w[r * k + c] = -f.s[r] * s_rc * sign;
      double q_rc = sign * ((r == c ? 1 : 0) - s_rc);
      for (int i = 0; i < r; ++i) q_rc += a[r * k + i] * f.w[i * k + c];  // row i of W is complete (i < r)
      f.q_top[r * k + c] = q_rc;
    }
}

// Sweep k, rows r >= k: Q(r, c) = sum_i x_i(r) W_ic, each row read before it is stored (q may
// be a or lie below it); then rows 0..k-1 from q_top.
template <int KC>
void form_q(const double* a, long n, int k_runtime, const Reflectors& f, double* q) {
  const int k = KC > 0 ? KC : k_runtime;
  double w_local[KC > 0 ? KC * KC : 1];  // in registers for compile-time k (q cannot alias it)
  const double* w = f.w;
  if constexpr (KC > 0) {
    for (int e = 0; e < k * k; ++e) w_local[e] = f.w[e];
    w = w_local;
  }
  for (long r = k; r < n; ++r) {
    const double* x = a + r * k;
    double row[capacity<KC>()];
    for (int c = 0; c < k; ++c) row[c] = x[0] * w[c];
    for (int i = 1; i < k; ++i)
      for (int c = 0; c < k; ++c) row[c] += x[i] * w[i * k + c];
    for (int c = 0; c < k; ++c) q[r * k + c] = row[c];
  }
  for (int e = 0; e < k * k; ++e) q[e] = f.q_top[e];
}

template <int KC>
void factor_sweeps(double* a, long n, int k_runtime, Reflectors& f) {
  const int k = KC > 0 ? KC : k_runtime;
  make_reflector(a, k, 0, f);
  if constexpr (KC > 0) {
    [&]<int... J>(std::integer_sequence<int, J...>) {
      ((sweep<KC, J + 1>(a, n, k, J + 1, f), make_reflector(a, k, J + 1, f)), ...);
    }
    (std::make_integer_sequence<int, KC - 1>{});
  } else {
    for (int j = 1; j < k; ++j) {
      sweep<0, -1>(a, n, k, j, f);
      make_reflector(a, k, j, f);
    }
  }
}

template <int KC>
struct Kernel {
  static void first(const double* a, long n, int k, Reflectors& f) { first_sweep<KC>(a, n, k, f); }
  static void factor(double* a, long n, int k, Reflectors& f) { factor_sweeps<KC>(a, n, k, f); }
  static void q(const double* a, long n, int k, const Reflectors& f, double* q) { form_q<KC>(a, n, k, f, q); }
};

// Compile-time k for the common small blocks, runtime k otherwise.
template <class Call>
void with_kernel(int k, Call&& call) {
  switch (k) {
    case 1: return call(Kernel<1>{});
    case 2: return call(Kernel<2>{});
    case 3: return call(Kernel<3>{});
    case 4: return call(Kernel<4>{});
    case 5: return call(Kernel<5>{});
    case 6: return call(Kernel<6>{});
    case 7: return call(Kernel<7>{});
    case 8: return call(Kernel<8>{});
    default: return call(Kernel<0>{});
  }
}

}  // namespace

TangentQR::TangentQR(double* block, long n, int k)
    : block_(block), n_(n), k_(k), scalars_(6 * static_cast<size_t>(k)), matrices_(4 * static_cast<size_t>(k) * k) {
  if (k > kMaxTangentVectors)
    throw BadInput("`exponents = " + std::to_string(k) + "`: at most " + std::to_string(kMaxTangentVectors) +
                   " tangent vectors");
}

void TangentQR::factorise(double* q_out, double* log_r) {
  const long n = n_;
  const int k = k_;
  double* const a = block_;
  double* const sc = scalars_.data();
  double* const mx = matrices_.data();
  Reflectors f{sc,         sc + k, sc + 2 * k, sc + 3 * k,     sc + 4 * k,
               sc + 5 * k, mx,     mx + k * k, mx + 2 * k * k, mx + 3 * k * k};
  with_kernel(k, [&](auto kernel) {
    using K = decltype(kernel);
    K::first(a, n, k, f);
    // Keep the squares in range: scale by a power of two (exact) when a column norm is far from
    // 1; the sums above are then recomputed. Non-finite entries also end up here.
    double biggest_sq = 0;
    bool bounded = true;  // false also for NaN
    for (int c = 0; c < k; ++c) {
      biggest_sq = std::max(biggest_sq, f.sq[c]);
      bounded = bounded && f.sq[c] <= kSquaresHigh;
    }
    double log_scale = 0;
    if (!bounded || biggest_sq < kSquaresLow) {
      double biggest = 0;
      for (long i = 0; i < n * k; ++i) {
        if (!std::isfinite(a[i])) throw NonFiniteResult("Lyapunov QR: the tangent block is not finite");
        biggest = std::max(biggest, std::abs(a[i]));
      }
      if (biggest > 0) {
        const int e = std::ilogb(biggest);
        for (long i = 0; i < n * k; ++i) a[i] = std::ldexp(a[i], -e);
        log_scale = e * std::log(2.0);
        K::first(a, n, k, f);
      }
    }
    // block = Q R (R in the upper triangle, the unscaled reflectors below)
    K::factor(a, n, k, f);
    for (int i = 0; i < k; ++i) {
      const double r = f.r[i];
      if (!std::isfinite(r))
        throw NonFiniteResult("Lyapunov QR: R(" + std::to_string(i) + "," + std::to_string(i) +
                               ") = " + format_number(r) + " (the tangent block is not finite)");
      const double norm = std::sqrt(f.sq[i]);
      if (!(std::abs(r) > dependence_threshold(n) * norm))
        throw NumericalFailure(
            "Lyapunov QR: tangent vector " + std::to_string(i + 1) +
            " became linearly dependent on the previous ones (|R_ii| = " + format_number(std::abs(r)) +
            ", below n eps times its norm " + format_number(norm) + "); fewer exponents, or a smaller qr_every");
      log_r[i] = std::log(std::abs(r)) + log_scale;
    }
    make_q_coefficients(a, k, f);
    K::q(a, n, k, f, q_out);
  });
}

}  // namespace delayspec
