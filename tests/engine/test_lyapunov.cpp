// Lyapunov exponents by QR reorthonormalisation (lyapunov.hpp), checked against what the code
// under test did not produce: exact characteristic roots (Lambert W), the same-N Floquet
// multipliers from the dense reference, identities of the QR, and the trajectory of
// StroboscopicMap.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "delayspec/detail/flush_subnormals.hpp"
#include "delayspec/lambert_w.hpp"
#include "delayspec/lyapunov.hpp"
#include "delayspec/model_impact.hpp"
#include "delayspec/model_linear.hpp"
#include "delayspec/model_mackey_glass.hpp"
#include "delayspec/model_mathieu.hpp"
#include "delayspec/orbit_simulation.hpp"
#include "test_support.hpp"

namespace ds = delayspec;
using ds::LyapunovOptions;
using ds::LyapunovResult;

namespace {

template <class Model>
ds::StroboscopicMap<Model> make_map(const Model& model, int N) {
  return ds::StroboscopicMap<Model>(ds::TrapezoidStepper<Model>(model), ds::make_grid(model.tau(), model.period(), N));
}

template <class Model>
LyapunovResult run(const Model& model, int N, LyapunovOptions o) {
  auto map = make_map(model, N);
  return ds::lyapunov_exponents(map, map.constant_history(model.initial_state()), o);
}

ds::LinearModel linear(double a, double b, double tau, double period) {
  ds::LinearParameters p;
  p.a = a;
  p.b = b;
  p.tau = tau;
  p.period = period;
  return ds::LinearModel(p);
}

}  // namespace

// ---- TangentQR: the QR step of the propagation, checked against identities and Eigen ----
//
// Householder QR is backward stable (Higham, Accuracy and Stability of Numerical Algorithms,
// 2nd ed., Thm 19.4 and 19.13): A + dA = Q R with |da_j| <= gamma(c n k) |a_j| and
// |Q^T Q - I| <= gamma(c n k), gamma(m) ~ m eps, for any A, whatever its condition number. The
// tests use 2 (n + k) k eps: the theorem's bound with c = 2, plus the rounding of the check's own
// products (Q^T Q, Q^T A, Q R: sums of n and k terms). Measured: up to 0.18 of it on the
// smallest blocks (n = 2), below 0.03 for n >= 20, ill-conditioned blocks included.

namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
constexpr double kEps = 2.220446049250313e-16;

double qr_bound(long n, int k) { return 2.0 * static_cast<double>(n + k) * k * kEps; }

struct TangentQrResult {
  RowMajor Q;
  std::vector<double> log_r;
};

// TangentQR on a copy of A (it factorises in place).
TangentQrResult tangent_qr(const RowMajor& A) {
  const long n = A.rows();
  const int k = static_cast<int>(A.cols());
  std::vector<double> block(A.data(), A.data() + n * k), q(n * k);
  TangentQrResult r{RowMajor(n, k), std::vector<double>(k)};
  ds::TangentQR qr(block.data(), n, k);
  qr.factorise(q.data(), r.log_r.data());
  r.Q = Eigen::Map<RowMajor>(q.data(), n, k);
  return r;
}

// The identities of a backward-stable QR with R_ii > 0, to `tol` (relative to the columns):
// Q^T Q = I; R = Q^T A is upper triangular (q_i orthogonal to a_0..a_{i-1}) with R_ii =
// exp(log_r[i]) > 0; Q R = A.
void expect_backward_stable_qr(const RowMajor& A, const TangentQrResult& r, double tol, const std::string& what) {
  const long k = A.cols();
  const Eigen::MatrixXd QtQ = r.Q.transpose() * r.Q, R = r.Q.transpose() * A;
  EXPECT_LT((QtQ - Eigen::MatrixXd::Identity(k, k)).cwiseAbs().maxCoeff(), tol) << what;
  for (int j = 0; j < k; ++j) {
    const double norm_j = A.col(j).norm();
    EXPECT_GT(R(j, j), 0) << what << ": R_jj > 0, j = " << j;
    EXPECT_NEAR(std::exp(r.log_r[j]), R(j, j), tol * norm_j) << what << ", j = " << j;
    for (int i = j + 1; i < k; ++i) EXPECT_NEAR(R(i, j), 0, tol * norm_j) << what << ", " << i << "," << j;
    EXPECT_LT((r.Q.leftCols(j + 1) * R.col(j).head(j + 1) - A.col(j)).norm(), tol * norm_j) << what << ", j = " << j;
  }
}

// Modified Gram-Schmidt: the test's witness that a block is hard. Its loss of orthogonality is
// ~ eps cond(A) (Bjorck 1967), so on the ill-conditioned blocks below it fails the bound that
// TangentQR must meet: the orthogonality check can fail.
double mgs_orthogonality_loss(const RowMajor& A) {
  Eigen::MatrixXd Q = A;
  for (int j = 0; j < Q.cols(); ++j) {
    for (int i = 0; i < j; ++i) Q.col(j) -= Q.col(i).dot(Q.col(j)) * Q.col(i);
    Q.col(j).normalize();
  }
  return (Q.transpose() * Q - Eigen::MatrixXd::Identity(Q.cols(), Q.cols())).cwiseAbs().maxCoeff();
}

RowMajor random_rows(long n, int k, std::uint64_t seed) {
  RowMajor A(n, k);
  ds::random_block(A.data(), n, k, seed);
  return A;
}

}  // namespace

// Every compile-time k (1..8) and the runtime path (k > 8, up to kMaxTangentVectors), square
// and tall blocks, odd and even n (the kernels take rows two at a time).
TEST(TangentQR, IsABackwardStableQrForEveryBlockWidth) {
  for (int k : {1, 2, 3, 4, 5, 6, 7, 8, 9, 16, 33, ds::kMaxTangentVectors})
    for (long n : {static_cast<long>(k), k + 1L, 57L, 200L}) {
      if (n < k) continue;
      const RowMajor A = random_rows(n, k, 1000 + 10 * k + n);
      expect_backward_stable_qr(A, tangent_qr(A), qr_bound(n, k),
                                "n = " + std::to_string(n) + ", k = " + std::to_string(k));
    }
}

// The layout-specific kernel against the reference kernel (Eigen's HouseholderQR, column-major)
// for every compile-time k and the runtime path, and for blocks far from unit scale or with
// column norms just inside and just outside the 2^+-300 scaling threshold (the power-of-two
// scaling path; entries 2^-1060 are subnormal). The reference factorises the same entries
// scaled back by the exact power of two.
TEST(TangentQR, MatchesEigenHouseholderQR) {
  const long n = 41;
  for (int k : {1, 2, 3, 4, 5, 6, 7, 8, 9, 13, 41}) {
    const RowMajor unit = random_rows(n, k, 100 + k);
    double largest_norm = 0;
    for (int j = 0; j < k; ++j) largest_norm = std::max(largest_norm, unit.col(j).norm());
    std::vector<std::pair<double, int>> scales;  // (factor, its binary exponent for the exact way back)
    for (int e : {0, 664, -664, 1000, -1000, -1060}) scales.push_back({std::ldexp(1.0, e), e});
    for (double edge : {0x1p300, 0x1p-300})
      for (double side : {0.99, 1.01}) {
        const double factor = edge * side / largest_norm;
        scales.push_back({factor, 0});  // not a power of two: the reference uses the scaled entries
      }
    for (const auto& [factor, e] : scales) {
      RowMajor A = unit * factor;
      const TangentQrResult r = tangent_qr(A);
      const double log_scale = e != 0 ? e * std::log(2.0) : 0;
      RowMajor reference_entries = A;
      if (e != 0) reference_entries = A.unaryExpr([e](double x) { return std::ldexp(x, -e); });
      const Eigen::HouseholderQR<Eigen::MatrixXd> reference{Eigen::MatrixXd(reference_entries)};
      const Eigen::MatrixXd Q_ref = reference.householderQ() * Eigen::MatrixXd::Identity(n, k);
      const std::string what = "k = " + std::to_string(k) + ", scale " + ds::format_number(factor);
      for (int i = 0; i < k; ++i) {
        const double r_ref = reference.matrixQR()(i, i);
        // both backward stable on a well-conditioned block: R agrees to O(n k eps) relative; the
        // logs are doubles of size |log R_ii| (~700 at 2^1000), each rounded to eps of that
        const double log_rounding = 4 * kEps * std::abs(r.log_r[i]);
        EXPECT_NEAR(r.log_r[i] - log_scale, std::log(std::abs(r_ref)), qr_bound(n, k) + log_rounding)
            << what << ", i = " << i;
        // same reflectors up to the sign convention fixed by R_ii > 0
        const double sign = r_ref < 0 ? -1 : 1;
        EXPECT_LT((r.Q.col(i) - sign * Q_ref.col(i)).cwiseAbs().maxCoeff(), qr_bound(n, k)) << what << ", i = " << i;
      }
    }
  }
}

// Blocks whose columns nearly align, as tangent vectors do between QR steps: A = Q0 R0 with R0
// graded (R0_jj from 1 down to 10^-p, O(1) above the diagonal: condition ~10^p) and A with
// columns a_0 + delta r_j. Householder keeps Q orthonormal to ~n k eps however ill-conditioned
// A is; modified Gram-Schmidt, run on the same block, loses ~eps 10^p (the check can fail).
// n is kept below 10^-p / eps, so no column is dependent in the n eps sense.
TEST(TangentQR, StaysOrthogonalOnIllConditionedBlocks) {
  for (int k : {2, 3, 4, 8, 9})
    for (int p : {8, 11, 14}) {
      const long n = p == 14 ? 21 : 301;
      const RowMajor G = random_rows(n, k, 7 * k + p);
      const Eigen::MatrixXd Q0 =
          Eigen::HouseholderQR<Eigen::MatrixXd>(Eigen::MatrixXd(G)).householderQ() * Eigen::MatrixXd::Identity(n, k);
      Eigen::MatrixXd R0 = random_rows(k, k, 3 * k + p).triangularView<Eigen::StrictlyUpper>();
      for (int j = 0; j < k; ++j) R0(j, j) = std::pow(10.0, -p * j / std::max(1.0, k - 1.0));
      const RowMajor A = Q0 * R0;
      const std::string what = "graded, k = " + std::to_string(k) + ", 10^-" + std::to_string(p);
      expect_backward_stable_qr(A, tangent_qr(A), qr_bound(n, k), what);
      EXPECT_GT(mgs_orthogonality_loss(A), 100 * qr_bound(n, k)) << what << ": the block is not hard";
    }
  for (int k : {2, 3, 5})
    for (double delta : {1e-6, 1e-10, 1e-12}) {
      const long n = 101;
      RowMajor A = random_rows(n, k, 11 * k);
      for (int j = 1; j < k; ++j) A.col(j) = A.col(0) + delta * A.col(j);
      const std::string what = "a_0 + delta r_j, k = " + std::to_string(k) + ", delta " + ds::format_number(delta);
      expect_backward_stable_qr(A, tangent_qr(A), qr_bound(n, k), what);
      if (delta < 1e-8) {
        EXPECT_GT(mgs_orthogonality_loss(A), 100 * qr_bound(n, k)) << what << ": the block is not hard";
      }
    }
}

// Q written over the block itself or into the same buffer a few rows before it (as the
// Lyapunov loop does: Q to slots 0..M, the block in slots K..K+M): the identities hold and Q is
// the one written to separate memory, bit for bit.
TEST(TangentQR, QMayOverwriteTheBlockFromBelow) {
  for (int k : {1, 2, 3, 8, 9}) {
    const long n = 45;
    const RowMajor A = random_rows(n, k, 77 + k);
    const TangentQrResult separate = tangent_qr(A);
    for (long offset : {0L, 1L, static_cast<long>(k) - 1, 3L * k}) {
      std::vector<double> buffer((n + offset) * k), log_r(k);
      double* const block = buffer.data() + offset * k;
      std::copy(A.data(), A.data() + n * k, block);
      ds::TangentQR qr(block, n, k);
      qr.factorise(buffer.data(), log_r.data());
      const TangentQrResult shared{Eigen::Map<RowMajor>(buffer.data(), n, k), log_r};
      const std::string what = "k = " + std::to_string(k) + ", Q " + std::to_string(offset) + " rows before the block";
      expect_backward_stable_qr(A, shared, qr_bound(n, k), what);
      EXPECT_EQ(shared.Q, separate.Q) << what;
    }
  }
}

// Non-finite entries anywhere (each column, the head row and a tail row, both parities of the
// row pairs) and columns dependent in the n eps sense are a NumericalFailure; a column just
// above the n eps test is not. One TangentQR object throughout: a failure leaves it usable.
TEST(TangentQR, NonFiniteOrDependentBlockIsANumericalFailure) {
  for (int k : {1, 2, 3, 9}) {
    const long n = 31;
    std::vector<double> block(n * k), q(n * k), log_r(k);
    ds::TangentQR qr(block.data(), n, k);
    for (double bad : {NAN, INFINITY, -INFINITY})
      for (int c = 0; c < k; ++c)
        for (long row : {0L, 1L, n - 2, n - 1}) {
          ds::random_block(block.data(), n, k, 5);
          block[row * k + c] = bad;
          EXPECT_THROW(qr.factorise(q.data(), log_r.data()), ds::NumericalFailure) << k << " " << c << " " << row;
        }
    const RowMajor good = random_rows(n, k, 6);
    for (int c = 0; c < k; ++c) {
      auto with_column = [&](const Eigen::VectorXd& column) {
        RowMajor A = good;
        A.col(c) = column;
        Eigen::Map<RowMajor>(block.data(), n, k) = A;
        return A;
      };
      with_column(Eigen::VectorXd::Zero(n));
      EXPECT_THROW(qr.factorise(q.data(), log_r.data()), ds::NumericalFailure) << "zero column " << c;
      if (c == 0) continue;
      // a_c = combination of earlier columns plus a part of relative size f (n eps is the threshold)
      const Eigen::VectorXd span_part = good.leftCols(c) * Eigen::VectorXd::LinSpaced(c, 1.0, 2.0);
      const Eigen::VectorXd noise = random_rows(n, 1, 40 + c).col(0);
      for (double f : {0.0, 0.01, 30.0}) {
        const Eigen::VectorXd column = span_part + f * n * kEps * span_part.norm() / noise.norm() * noise;
        const RowMajor A = with_column(column);
        if (f < 1) {
          EXPECT_THROW(qr.factorise(q.data(), log_r.data()), ds::NumericalFailure) << "dependent column " << c;
        } else {  // |R_cc| ~ 30 n eps |a_c| (the noise is mostly orthogonal to the span): kept
          qr.factorise(q.data(), log_r.data());
          TangentQrResult r{Eigen::Map<RowMajor>(q.data(), n, k), log_r};
          expect_backward_stable_qr(A, r, qr_bound(n, k), "nearly dependent column " + std::to_string(c));
        }
      }
    }
  }
}

TEST(Lyapunov, RandomBlockIsReproducible) {
  std::vector<double> a(30), b(30), c(30);
  ds::random_block(a.data(), 10, 3, 42);
  ds::random_block(b.data(), 10, 3, 42);
  ds::random_block(c.data(), 10, 3, 43);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  for (double x : a) EXPECT_TRUE(x >= -0.5 && x < 0.5);
}

// x' = -x - 2 x(t - 1): rightmost roots -0.0925 +- 2.00i and -1.363 +- 7.81i. Four exponents
// per unit time (T = 1): two equal to Re of each complex pair.
TEST(Lyapunov, LinearDdeExponentsAreRealPartsOfExactRoots) {
  const auto model = linear(-1, -2, 1, 1);
  const int N = 100;
  const auto roots = ds::linear_dde_roots(-1, -2, 1, 3);
  const auto mu = ds::testing::dense_multipliers(model, N, 4);
  LyapunovOptions o;
  o.exponents = 4;
  o.transient = 100;  // the block aligns at the rate |mu_5 / mu_4| = e^{-0.59} per period: e^-59 after 100
  o.periods = 1000;
  const LyapunovResult short_run = run(model, N, o);
  o.periods = 16000;
  const LyapunovResult long_run = run(model, N, o);
  for (int i = 0; i < 4; ++i) {
    const double exact = roots[i].real();                 // roots come sorted by real part
    const double same_N = std::log(std::abs(mu[i])) / 1;  // the discrete map's own value, T = 1
    // trapezoid rule: O(h^2) discretisation error, h = 1e-2, constant |lambda|^3/12 ~ 40 for the second pair
    EXPECT_NEAR(same_N, exact, 40 * 1e-4) << i;
    for (const LyapunovResult* r : {&short_run, &long_run}) {
      // statistical agreement with the same-N value: 3 standard errors
      EXPECT_NEAR(r->per_time[i], same_N, 3 * r->error_per_time[i]) << i << " periods " << r->periods;
      // against the exact root: statistics plus the discretisation error just bounded
      EXPECT_NEAR(r->per_time[i], exact, 3 * r->error_per_time[i] + std::abs(same_N - exact)) << i;
    }
    // 16x the run: the quasi-periodic fluctuation of a complex pair averages out like 1/periods,
    // noise like 1/sqrt(periods); either way the error estimate shrinks by more than 3x
    EXPECT_LT(long_run.error_per_time[i], short_run.error_per_time[i] / 3) << i;
    EXPECT_GT(long_run.error_per_time[i], 0) << i;
  }
  EXPECT_EQ(long_run.periods, 16000);
  EXPECT_DOUBLE_EQ(long_run.map_time, 1.0);
}

// A stable delayed Mathieu point whose leading multipliers are real and simple:
// mu = -0.690, -0.346, 0.307, ... (N = 100). The block converges to the leading two-dimensional
// Floquet subspace at the rate |mu_3 / mu_2| = 0.887 per period; after a transient of 400
// periods the misalignment is 0.887^400 ~ 1e-21, so every measured period contributes exactly
// log |mu_1| and log |mu_2| up to rounding.
TEST(Lyapunov, StableMathieuPointGivesLogOfFloquetMultipliers) {
  ds::MathieuParameters p;
  p.kappa = 0.6;
  p.delta = 0.25;
  p.eps = 0.6;
  p.b = 0.1;
  const ds::MathieuModel model(p);
  const int N = 100;
  const auto mu = ds::testing::dense_multipliers(model, N, 3);
  ASSERT_LT(std::abs(mu[0]), 1);
  ASSERT_EQ(mu[0].imag(), 0);
  ASSERT_EQ(mu[1].imag(), 0);
  LyapunovOptions o;
  o.exponents = 2;
  o.transient = 400;
  o.periods = 200;
  const LyapunovResult r = run(model, N, o);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(r.per_period[i], std::log(std::abs(mu[i])), 1e-6) << i;  // the bound
    // and in fact to rounding: each period's QR is backward stable, ~ n eps relative
    EXPECT_NEAR(r.per_period[i], std::log(std::abs(mu[i])), 1e-11) << i;
    EXPECT_NEAR(r.per_time[i], r.per_period[i] / (2 * std::numbers::pi), 1e-15) << i;
    // Real multipliers, aligned block: every period contributes the same log R_ii up to
    // rounding, so the reported error stays at rounding level too (the fluctuation bound adds
    // nothing here: D(i) is a sum of roundings, ~ i eps per period at most).
    std::printf("mathieu aligned: lambda_%d err %.3e (batch SE %.3e, fluctuation bound %.3e)\n", i + 1,
                r.error_per_period[i], r.batch_standard_error_per_period[i], r.fluctuation_bound_per_period[i]);
    EXPECT_LT(r.error_per_period[i], 1e-12) << i;
  }
}

// The same Mathieu point without a transient: the random start block aligns with the leading
// Floquet directions at the rates |mu_2 / mu_1| = 0.50 and |mu_3 / mu_2| = 0.89 per period, so the
// first periods add a bounded excess E to the sums of log R_ii (a deterministic bias E / periods,
// like the phase term of a complex pair). The error must cover it, and stay tight. The excess
// builds up in the first i0 periods (i0 << 20, one batch): then SE = E / periods exactly (one
// batch mean off) and F = E (1 - i0 / I) / periods, so the error is sqrt(2) E / periods; where the
// excess overshoots on its way (lambda_2: the second direction first picks up part of the third),
// F is the overshoot's range, measured ~2 E / periods. Asked: deviation <= error <= 3 deviation.
TEST(Lyapunov, RealMultipliersWithoutTransientErrorCoversTheAlignmentBiasTightly) {
  ds::MathieuParameters p;
  p.kappa = 0.6;
  p.delta = 0.25;
  p.eps = 0.6;
  p.b = 0.1;
  const ds::MathieuModel model(p);
  const int N = 100;
  const auto mu = ds::testing::dense_multipliers(model, N, 3);
  LyapunovOptions o;
  o.exponents = 2;
  o.transient = 0;
  o.periods = 400;
  const LyapunovResult r = run(model, N, o);
  for (int i = 0; i < 2; ++i) {
    const double deviation = std::abs(r.per_period[i] - std::log(std::abs(mu[i])));
    std::printf("mathieu no transient: lambda_%d deviation %.3e err %.3e (batch SE %.3e, fluctuation bound %.3e)\n",
                i + 1, deviation, r.error_per_period[i], r.batch_standard_error_per_period[i],
                r.fluctuation_bound_per_period[i]);
    EXPECT_LE(deviation, r.error_per_period[i]) << i;
    EXPECT_LE(r.error_per_period[i], 3 * deviation) << i;
  }
}

// The impact oscillator's period-1 orbit at tau = T, k = 1 (found by simulation from the default
// scene's history, N = 200). Its leading multipliers are a complex pair mu, conj(mu) (|mu| =
// 0.98), then another pair of modulus 0.76. For a complex pair the individual values log R_11,
// log R_22 oscillate with the phase of the rotation, but the area growth of the invariant plane
// is exactly |mu|^2 every period once the block has aligned: log R_11 + log R_22 = 2 log |mu|.
// Alignment rate |mu_3 / mu_1| = 0.77: after 300 periods 1e-34.
// Individually: on the plane spanned by S = [Re v, Im v] (v the eigenvector of mu) the monodromy
// is |mu| S Rot S^+, so prod R_11 = |M^n q| = |mu|^n |S Rot(n arg mu) S^+ q| with the last factor
// in [1/cond(S), cond(S)]: |lambda_i - log|mu|| <= log cond(S) / periods, a deterministic bound
// (the batch-means error bar does not bound this phase term; docs/lyapunov.md).
TEST(Lyapunov, ImpactPeriodOneOrbitGivesLogOfFloquetMultipliers) {
  ds::ImpactParameters p;
  p.k = 1.0;
  p.x0 = -0.0566;
  p.v0 = 1.0101;
  const ds::ImpactModel model(p);
  const int N = 200;
  auto map = make_map(model, N);
  ds::OrbitBySimulationOptions so;
  so.tolerance = 1e-13;
  so.max_maps = 5000;
  const ds::PeriodicOrbit orbit = ds::orbit_by_simulation(map, map.constant_history(model.initial_state()), so);
  ds::FloquetOptions fo;
  fo.nev = 3;
  fo.solver = ds::FloquetSolver::dense_lapack;
  const auto mu = ds::floquet_multipliers(map.monodromy(orbit.history), fo).multipliers;
  ASSERT_LT(std::abs(mu[0]), 1);
  ASSERT_NEAR(std::abs(mu[0]), std::abs(mu[1]), 1e-12);  // a complex pair
  LyapunovOptions o;
  o.exponents = 2;
  o.transient = 300;
  o.periods = 400;
  const LyapunovResult r = ds::lyapunov_exponents(map, orbit.history, o);
  const double log_mu = std::log(std::abs(mu[0]));
  EXPECT_NEAR(r.per_period[0] + r.per_period[1], 2 * log_mu, 1e-6);  // the bound
  // individually: within the phase bound log cond(S) / periods (cond(S) from the dense eigenvector)
  const Eigen::EigenSolver<Eigen::MatrixXd> eig(map.monodromy(orbit.history).to_dense());
  Eigen::Index lead = 0;
  for (Eigen::Index i = 1; i < eig.eigenvalues().size(); ++i)
    if (std::abs(eig.eigenvalues()[i]) > std::abs(eig.eigenvalues()[lead]) + 1e-12 ||
        (std::abs(std::abs(eig.eigenvalues()[i]) - std::abs(eig.eigenvalues()[lead])) <= 1e-12 &&
         eig.eigenvalues()[i].imag() > eig.eigenvalues()[lead].imag()))
      lead = i;
  const std::complex<double> mu_upper = mu[0].imag() > 0 ? mu[0] : mu[1];
  ASSERT_LT(std::abs(eig.eigenvalues()[lead] - mu_upper), 1e-10);  // two dense solvers agree
  Eigen::MatrixXd S(eig.eigenvectors().rows(), 2);
  S << eig.eigenvectors().col(lead).real(), eig.eigenvectors().col(lead).imag();
  const Eigen::VectorXd sigma = Eigen::JacobiSVD<Eigen::MatrixXd>(S).singularValues();
  const double phase_bound = std::log(sigma[0] / sigma[1]) / o.periods;
  for (int i = 0; i < 2; ++i) EXPECT_NEAR(r.per_period[i], log_mu, phase_bound + 1e-12) << i;
  // The reported error covers that phase term: the interval lambda_i +- error contains log|mu|
  // (log|mu| from the dense solver, which the Lyapunov code did not produce). The batch-means
  // standard error alone does not: the rotation per batch of 20 periods is close to a multiple of
  // 2 pi here, every batch sees the same phase change, and the batch means agree to ~2e-6 while
  // the exponents are off by ~1.1e-4 (a named regression of the old error bar: 60 SE).
  for (int i = 0; i < 2; ++i) {
    std::printf(
        "impact pair: lambda_%d %.9f err %.3e (batch SE %.3e, fluctuation bound %.3e), |lambda - log|mu|| %.3e, phase bound %.3e\n",
        i + 1, r.per_period[i], r.error_per_period[i], r.batch_standard_error_per_period[i],
        r.fluctuation_bound_per_period[i], std::abs(r.per_period[i] - log_mu), phase_bound);
    EXPECT_LE(std::abs(r.per_period[i] - log_mu), r.error_per_period[i]) << i;
    EXPECT_GT(std::abs(r.per_period[i] - log_mu), 10 * r.batch_standard_error_per_period[i]) << i;
    // and it is no looser than the a-priori bound: g in [-log cond S, log cond S] with g(0) = 0
    // (the block starts in the plane) gives range D <= range g + |g(I)| <= 3 log cond S
    EXPECT_LE(r.error_per_period[i], 3 * phase_bound) << i;
  }
  // the run stays on the orbit: final history equals the orbit to the simulation tolerance
  EXPECT_LT((r.final_history - orbit.history).lpNorm<Eigen::Infinity>(), 1e-9);
}

// Mackey-Glass, tau = 17 (chaotic): the exponents must not depend on the seed of the initial
// block, nor on the QR interval, beyond the stated errors.
TEST(Lyapunov, SeedAndQrIntervalChangeResultsOnlyWithinTheError) {
  ds::MackeyGlassParameters p;
  p.tau = 17;
  p.period = 17;
  p.x0 = 0.5;
  const ds::MackeyGlassModel model(p);
  const int N = 85;  // h = 0.2
  LyapunovOptions o;
  o.exponents = 2;
  o.transient = 100;
  o.periods = 1200;
  std::vector<LyapunovResult> runs;
  for (auto [seed, every] : {std::pair{1, 1}, {2, 1}, {3, 1}, {1, 3}, {2, 4}}) {
    o.seed = seed;
    o.qr_every = every;
    runs.push_back(run(model, N, o));
  }
  for (size_t a = 1; a < runs.size(); ++a)
    for (int i = 0; i < 2; ++i) {
      // the same trajectory in every run, so the difference is the tangent block's start and
      // the QR schedule: bounded by 4 combined standard errors (independent-error bound is 3;
      // the runs share the trajectory, which only makes them closer)
      const double se = std::hypot(runs[0].error_per_period[i], runs[a].error_per_period[i]);
      EXPECT_NEAR(runs[a].per_period[i], runs[0].per_period[i], 4 * se) << "run " << a << " exponent " << i;
    }
  EXPECT_GT(runs[0].per_period[0], 0) << "tau = 17 is chaotic: lambda_1 > 0";
  // lambda_2 is the flow direction (zero) up to the error
  EXPECT_NEAR(runs[0].per_period[1], 0, 4 * runs[0].error_per_period[1] + 0.01);
}

// Chaos: the reported error must be of the order of the actual scatter of the exponent, measured
// as the spread of 12 independent estimates (consecutive windows of 1000 periods of one chaotic
// trajectory, each a fresh run from the previous window's end). With 12 windows the sample sd is
// within a factor 2 of the true sd with probability > 99 % (chi-square, 11 degrees of freedom).
// lambda_1 (random-walk fluctuations): the error estimates ~1.6 sd (header comment), asked within
// [1/3, 3] of the windows' sd. lambda_2 (the flow direction) fluctuates boundedly (log |x'(t)|
// along the orbit) with a random end phase: both the old batch SE (random-walk scaling, ~sqrt(B)
// too large) and F are conservative there; asked: the error covers the spread. For both: the new
// error is below 2x the old batch SE (on noise sqrt(1 + 1.25^2) = 1.6 is expected; the batch SE
// of one window is itself uncertain by ~1 / sqrt(2 (B - 1)) = 16 %).
TEST(Lyapunov, ChaoticErrorMatchesTheSpreadOfIndependentWindows) {
  ds::MackeyGlassParameters p;
  p.tau = 17;
  p.period = 17;
  p.x0 = 0.5;
  const ds::MackeyGlassModel model(p);
  const int N = 85;  // h = 0.2
  auto map = make_map(model, N);
  Eigen::VectorXd U = map.constant_history(model.initial_state());
  LyapunovOptions o;
  o.exponents = 2;
  o.transient = 100;  // first window: onto the attractor; later ones: the block aligns (gap 0.66 per period)
  o.periods = 1000;
  const int windows = 12;
  std::vector<std::vector<double>> value(2), error(2), batch(2);
  for (int w = 0; w < windows; ++w) {
    const LyapunovResult r = ds::lyapunov_exponents(map, U, o);
    for (int i = 0; i < 2; ++i) {
      value[i].push_back(r.per_period[i]);
      error[i].push_back(r.error_per_period[i]);
      batch[i].push_back(r.batch_standard_error_per_period[i]);
    }
    U = r.final_history;
    o.transient = 30;
    o.seed = w + 2;
  }
  for (int i = 0; i < 2; ++i) {
    double mean = 0, mean_error = 0, mean_batch = 0;
    for (int w = 0; w < windows; ++w)
      mean += value[i][w] / windows, mean_error += error[i][w] / windows, mean_batch += batch[i][w] / windows;
    double ss = 0;
    for (int w = 0; w < windows; ++w) ss += (value[i][w] - mean) * (value[i][w] - mean);
    const double sd = std::sqrt(ss / (windows - 1));
    std::printf(
        "mackey-glass lambda_%d: mean %.6f, sd of %d windows %.3e, mean reported error %.3e (ratio %.2f), batch SE %.3e\n",
        i + 1, mean, windows, sd, mean_error, mean_error / sd, mean_batch);
    EXPECT_GE(mean_error, sd) << i;
    EXPECT_LT(mean_error, 2 * mean_batch) << i;
    if (i == 0) {
      EXPECT_GT(mean_error, sd / 3);
      EXPECT_LT(mean_error, 3 * sd);
    }
  }
}

// lyapunov_statistics on sequences whose answer is known.
// (a) A bounded oscillation resonant with the batches: x_i = c + A (cos(theta i) - cos(theta (i - 1))),
// so S(i) = i c + A (cos(theta i) - 1) and the mean is off by A (cos(theta I) - 1) / I exactly.
// theta = 2 pi / 20 + pi / I: every batch of 20 intervals sees almost the same phase change (the
// phase drifts by pi over the whole run, so the bias is the largest possible, -2 A / I); the batch
// means nearly agree and the batch SE is ~9x smaller than the bias; the error covers it.
TEST(LyapunovStatistics, BoundedOscillationResonantWithTheBatchesIsCovered) {
  const long I = 400;
  const double c = -0.3, A = 0.05, theta = 2 * std::numbers::pi / 20 + std::numbers::pi / I;
  std::vector<double> x(I);
  for (long i = 1; i <= I; ++i) x[i - 1] = c + A * (std::cos(theta * i) - std::cos(theta * (i - 1)));
  const ds::LyapunovStatistics st = ds::lyapunov_statistics(x, 1, 1, 20);
  const double bias = A * (std::cos(theta * I) - 1) / I;
  EXPECT_NEAR(st.mean_per_period[0] - c, bias, 1e-15);        // the mean is S(I) / I, rounding only
  EXPECT_NEAR(bias, -2 * A / I, 1e-12);                       // cos(theta I) = cos(41 pi) = -1
  EXPECT_LT(st.batch_standard_error[0], std::abs(bias) / 5);  // the old error bar: blind
  EXPECT_GE(st.error[0], std::abs(bias));
  // range of D <= range of the oscillation plus |bias| I: (2 A + |bias| I) / I
  EXPECT_LE(st.fluctuation_bound[0], (2 * A + std::abs(bias) * I) / I + 1e-15);
}

// (b) Independent noise: the range of a Brownian bridge has mean sqrt(pi / 2) sigma sqrt(n)
// (Kuiper), so F / (sigma / sqrt(n)) averages sqrt(pi / 2) = 1.2533 (a discrete walk of n = 2000
// steps a little less, by O(1 / sqrt(n))). Over 200 sequences the mean has a standard error of
// 0.27 / sqrt(200) = 0.02 (sd of the bridge range 0.27 sigma sqrt(n)): asked within [1.15, 1.31].
// The reported error max(SE, F) then averages well below 2 sigma / sqrt(n): noise is not inflated.
TEST(LyapunovStatistics, OnIndependentNoiseTheBoundIsAboutOnePointTwoFiveStandardErrors) {
  const long n = 2000;
  const int sequences = 200;
  const double sigma = 0.1;
  std::mt19937_64 engine(7);
  std::normal_distribution<double> normal(0.0, sigma);
  double ratio = 0, reported = 0;
  std::vector<double> x(n);
  for (int q = 0; q < sequences; ++q) {
    for (double& v : x) v = 0.5 + normal(engine);
    const ds::LyapunovStatistics st = ds::lyapunov_statistics(x, 1, 1, 20);
    ratio += st.fluctuation_bound[0] / (sigma / std::sqrt(double(n))) / sequences;
    reported += st.error[0] / (sigma / std::sqrt(double(n))) / sequences;
  }
  std::printf("noise: mean F / (sigma/sqrt n) = %.3f, mean error / (sigma/sqrt n) = %.3f\n", ratio, reported);
  EXPECT_GT(ratio, 1.15);
  EXPECT_LT(ratio, 1.31);
  EXPECT_LT(reported, 2.0);
}

TEST(Lyapunov, TooLongQrIntervalIsRefused) {
  // x' = -x - 2 x(t - 1): exponents -0.09 and -1.36 per period. Over 20 periods the block's
  // columns separate by e^{1.27 * 20} ~ 1e11 > 1e8: the run must refuse rather than lose digits.
  LyapunovOptions o;
  o.exponents = 4;
  o.transient = 0;
  o.periods = 40;
  o.qr_every = 20;
  EXPECT_THROW(run(linear(-1, -2, 1, 1), 40, o), ds::NumericalFailure);
  o.qr_every = 2;  // e^2.5 ~ 12: fine
  EXPECT_NO_THROW(run(linear(-1, -2, 1, 1), 40, o));
}

// x' = -50 x + x(t - 1), N = 20 (h = 0.05): the rightmost roots have Re lambda ~ -ln(50) / tau
// = -3.8, so the tangent vectors shrink by e^-3.8 per period (and the local step by 0.11 per
// step): an unnormalised product would underflow below 1e-308 after about 190 periods. Over
// 1e5 periods, 500 times longer, the exponents must stay finite and equal log|mu| of the
// same-N multipliers.
TEST(Lyapunov, StaysFiniteOverManyPeriodsOfStrongContraction) {
  const auto model = linear(-50, 1, 1, 1);
  const int N = 20;
  LyapunovOptions o;
  o.exponents = 2;
  o.transient = 100;
  o.periods = 100000;
  const LyapunovResult r = run(model, N, o);
  const auto mu = ds::testing::dense_multipliers(model, N, 2);
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(std::isfinite(r.per_period[i])) << i;
    ASSERT_TRUE(std::isfinite(r.error_per_period[i])) << i;
    EXPECT_LT(r.per_period[i], -3.5) << i;  // contracting as computed above
    // the same-N value to the error, plus the log of a relative rounding of R_ii per period
    EXPECT_NEAR(r.per_period[i], std::log(std::abs(mu[i])), 3 * r.error_per_period[i] + 1e-9) << i;
  }
}

// The guard a Lyapunov period runs under: inside it a product with a subnormal result is 0 and a
// subnormal input counts as 0; afterwards both are back (the caller's mode is restored).
TEST(FlushSubnormals, FlushesWhileAliveAndRestoresTheCallersMode) {
  volatile double tiny = 0x1p-1000, small = 0x1p-50;  // volatile: computed at run time
  volatile double subnormal = 0x1p-1060;              // below the least normal 2^-1022
  ASSERT_GT(tiny * small, 0.0);                       // 2^-1050: subnormal in the default mode
  ASSERT_GT(subnormal * 2.0, 0.0);
  {
    const ds::detail::FlushSubnormals flush;
#if defined(__SSE__) || defined(__x86_64__) || defined(__aarch64__)
    EXPECT_EQ(tiny * small, 0.0);     // result flushed
    EXPECT_EQ(subnormal * 2.0, 0.0);  // input treated as zero (DAZ; FZ on AArch64)
#endif
    EXPECT_EQ(small * small, 0x1p-100);  // normal numbers untouched
  }
  EXPECT_EQ(tiny * small, 0x1p-1050);
  EXPECT_EQ(subnormal * 2.0, 0x1p-1059);
}

// x' = -x + 0.5 x(t - tau), tau = T = 7.83 (the docs' scalar benchmark): the trajectory decays by
// e^-0.61 per period and would be subnormal after ~1160 periods; with subnormals flushed it
// stops near 1e-306, where its increments h/2 f underflow. The exponents over 1500 periods
// after that equal log |mu| of the same-N multipliers (the map of a linear model does not
// depend on the trajectory): to the error, as in the long run above.
TEST(Lyapunov, ATrajectoryDecayedToTheSubnormalRangeLeavesTheExponentsUnchanged) {
  const double tau = 7.834395644862327;
  const auto model = linear(-1, 0.5, tau, tau);
  const int N = 100;
  LyapunovOptions o;
  o.exponents = 2;
  o.transient = 1300;
  o.periods = 1500;
  const LyapunovResult r = run(model, N, o);
  EXPECT_LT(r.final_history.lpNorm<Eigen::Infinity>(), 1e-300);  // decayed to the underflow range
  const auto mu = ds::testing::dense_multipliers(model, N, 2);
  for (int i = 0; i < 2; ++i)
    EXPECT_NEAR(r.per_period[i], std::log(std::abs(mu[i])), 3 * r.error_per_period[i] + 1e-9) << i;
}

TEST(Lyapunov, OverflowIsANumericalFailure) {
  // x' = 800 x: the trapezoid factor (1 + 0.4) / (1 - 0.4) per step at N = 1000 grows by e^847
  // per period: beyond the largest double.
  LyapunovOptions o;
  o.exponents = 1;
  o.transient = 0;
  o.periods = 4;
  EXPECT_THROW(run(linear(800, 0, 1, 1), 1000, o), ds::NumericalFailure);
}

TEST(Lyapunov, BadOptionsAreBadInput) {
  const auto model = linear(-1, 0.5, 1, 1);
  auto bad = [&](auto change) {
    LyapunovOptions o;
    o.periods = 10;
    o.transient = 0;
    change(o);
    EXPECT_THROW(run(model, 10, o), ds::BadInput);
  };
  bad([](LyapunovOptions& o) { o.exponents = 0; });
  bad([](LyapunovOptions& o) { o.exponents = 12; });  // n = 11
  bad([](LyapunovOptions& o) { o.qr_every = 0; });
  bad([](LyapunovOptions& o) { o.qr_every = 3; });  // 10 periods: not a multiple
  bad([](LyapunovOptions& o) { o.periods = 1; });
  bad([](LyapunovOptions& o) { o.transient = -1; });
  bad([](LyapunovOptions& o) { o.batches = 1; });
  auto map = make_map(model, 10);
  Eigen::VectorXd U = map.constant_history(model.initial_state());
  U[3] = NAN;
  EXPECT_THROW(ds::lyapunov_exponents(map, U, LyapunovOptions{}), ds::BadInput);
  EXPECT_THROW(ds::lyapunov_exponents(map, Eigen::VectorXd::Zero(5), LyapunovOptions{}), ds::BadInput);
}

TEST(Lyapunov, SectionPointsAreTheTrajectoryAtEveryForcingPeriod) {
  ds::ImpactParameters p;
  p.k = 0.02;
  p.x0 = 0.5;
  const ds::ImpactModel model(p);
  auto map = make_map(model, 50);
  LyapunovOptions o;
  o.exponents = 1;
  o.transient = 3;
  o.periods = 4;
  o.section_points = 3;
  const Eigen::VectorXd U0 = map.constant_history(model.initial_state());
  const LyapunovResult r = ds::lyapunov_exponents(map, U0, o);
  ASSERT_EQ(r.section.rows(), 3);
  Eigen::VectorXd U = U0;
  for (int i = 0; i < o.transient; ++i) U = map.apply(U);
  for (int i = 0; i < 3; ++i) {
    U = map.apply(U);
    // the same arithmetic in the same order: equal to the last bit
    EXPECT_EQ(r.section(i, 0), U[U.size() - 2]) << i;
    EXPECT_EQ(r.section(i, 1), U[U.size() - 1]) << i;
  }
}
