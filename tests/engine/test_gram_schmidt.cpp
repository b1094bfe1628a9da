// The Gram-Schmidt kernels of the Krylov-Schur backend (detail/gram_schmidt.hpp) against Eigen's
// products, for every column remainder of the four-column sweeps, a partial last chunk of rows,
// and 1, 2 and 3 threads (which must give the same bits: sums are added in chunk order), on both
// kernel paths: the portable one (forced by DELAYSPEC_KERNEL=baseline) and the one the CPU gets
// (AVX2 + FMA where it has them, src/engine/kernels/gram_schmidt_avx2.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Dense>

#include "delayspec/detail/gram_schmidt.hpp"
#include "test_support.hpp"

namespace delayspec::detail {
namespace {

// Three whole chunks and a partial one.
constexpr long kRows = 3 * kGramSchmidtRows + 123;

// "baseline": the portable path; "auto": the CPU's (the same one on a CPU without AVX2 + FMA).
constexpr const char* kPaths[] = {"baseline", "auto"};

// A dot product of n terms computed in any order is within n eps sum |a_i b_i| <= n eps |a| |b| of
// the exact value (Higham, Accuracy and Stability, 3.1); both the kernel and Eigen are, so they
// differ by at most twice that.
double dot_bound(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return 2.0 * static_cast<double>(a.size()) * std::numeric_limits<double>::epsilon() * a.norm() * b.norm();
}

TEST(GramSchmidt, CoefficientsMatchEigenForEveryColumnCountAndThreadCount) {
  for (const char* path : kPaths) {
    testing::KernelEnv env(path);
    SCOPED_TRACE(path);
    for (long j : {0L, 1L, 3L, 4L, 5L, 8L, 9L}) {
      SCOPED_TRACE("columns " + std::to_string(j));
      const Eigen::MatrixXd Q = testing::random_matrix(kRows, j, 11 + j);
      const Eigen::VectorXd x = testing::random_matrix(kRows, 1, 2), y = testing::random_matrix(kRows, 1, 3);
      const Eigen::VectorXd s_ref = Q.transpose() * x, t_ref = Q.transpose() * y;
      std::vector<double> first_s, first_t;
      for (int threads : {1, 2, 3}) {
        std::vector<double> s(j), t(j), s_alone(j);
        basis_coefficients(Q.data(), kRows, j, x.data(), y.data(), s.data(), t.data(), threads);
        basis_coefficients(Q.data(), kRows, j, x.data(), nullptr, s_alone.data(), nullptr, threads);
        for (long c = 0; c < j; ++c) {
          EXPECT_NEAR(s[c], s_ref[c], dot_bound(Q.col(c), x));
          EXPECT_NEAR(t[c], t_ref[c], dot_bound(Q.col(c), y));
          EXPECT_EQ(s_alone[c], s[c]);  // one vector or two: the same sums
        }
        if (threads == 1) {
          first_s = s;
          first_t = t;
        } else {
          EXPECT_EQ(s, first_s) << threads << " threads";
          EXPECT_EQ(t, first_t) << threads << " threads";
        }
      }
    }
  }
}

TEST(GramSchmidt, SubtractionAndProductsMatchEigen) {
  for (const char* path : kPaths) {
    testing::KernelEnv env(path);
    SCOPED_TRACE(path);
    for (long j : {0L, 1L, 4L, 6L, 7L}) {
      SCOPED_TRACE("columns " + std::to_string(j));
      const Eigen::MatrixXd Q = testing::random_matrix(kRows, j, 21 + j);
      const Eigen::VectorXd x0 = testing::random_matrix(kRows, 1, 4), y0 = testing::random_matrix(kRows, 1, 5);
      const Eigen::VectorXd s = testing::random_matrix(j, 1, 6), t = testing::random_matrix(j, 1, 7);
      const Eigen::VectorXd x_ref = x0 - Q * s, y_ref = y0 - Q * t;
      Eigen::VectorXd first_x;
      for (int threads : {1, 2, 3}) {
        Eigen::VectorXd x = x0, y = y0, x_alone = x0;
        const ProjectedProducts p =
            subtract_in_basis(Q.data(), kRows, j, s.data(), t.data(), x.data(), y.data(), threads);
        const ProjectedProducts p_alone =
            subtract_in_basis(Q.data(), kRows, j, s.data(), nullptr, x_alone.data(), nullptr, threads);
        // Each entry is a sum of j + 1 terms: within (j + 1) eps (|x0_i| + sum |Q_ic s_c|) of exact.
        const double q_max = j > 0 ? Q.cwiseAbs().maxCoeff() : 0.0;  // maxCoeff of nothing is undefined
        const double entry_bound = 2.0 * static_cast<double>(j + 1) * std::numeric_limits<double>::epsilon() *
                                   (x0.cwiseAbs().maxCoeff() + q_max * s.cwiseAbs().sum() + y0.cwiseAbs().maxCoeff() +
                                    q_max * t.cwiseAbs().sum());
        EXPECT_LE((x - x_ref).cwiseAbs().maxCoeff(), entry_bound);
        EXPECT_LE((y - y_ref).cwiseAbs().maxCoeff(), entry_bound);
        EXPECT_EQ(x_alone, x);
        EXPECT_NEAR(p.xx, x.squaredNorm(), dot_bound(x, x));
        EXPECT_NEAR(p.xy, x.dot(y), dot_bound(x, y));
        EXPECT_NEAR(p.yy, y.squaredNorm(), dot_bound(y, y));
        EXPECT_EQ(p_alone.xx, p.xx);
        EXPECT_EQ(p_alone.xy, 0.0);
        if (threads == 1) first_x = x;
        else EXPECT_EQ(x, first_x) << threads << " threads";
      }
    }
  }
}

TEST(GramSchmidt, DivideAndSplitMatchesItsFormula) {
  const Eigen::VectorXd u0 = testing::random_matrix(kRows, 1, 8), w = testing::random_matrix(kRows, 1, 9);
  const double r = 0.37, g = -1.9;
  const Eigen::VectorXd q_ref = u0 / r, z_ref = (w - g * q_ref) / r;
  for (int threads : {1, 2, 3}) {
    Eigen::VectorXd u = u0, z(kRows);
    divide_and_split(kRows, r, g, u.data(), w.data(), z.data(), threads);
    // a product by 1 / r against a division: a few ulps of each entry
    EXPECT_LE((u - q_ref).cwiseAbs().maxCoeff(), 4e-16 * q_ref.cwiseAbs().maxCoeff()) << threads;
    EXPECT_LE((z - z_ref).cwiseAbs().maxCoeff(),
              1e-15 * (w.cwiseAbs().maxCoeff() + std::abs(g) * q_ref.cwiseAbs().maxCoeff()) / r)
        << threads;
  }
}

// The AVX2 path really runs where the CPU has it: its sums (four lanes, fused multiply-adds) round
// differently from the portable ones somewhere in 24 699 rows x 9 columns, and agree with them to
// the bound of the tests above. Without AVX2 + FMA, auto is the portable path, bit for bit.
TEST(GramSchmidt, TheWidePathRunsWhereTheCpuHasIt) {
  const bool wide = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  const long j = 9;
  const Eigen::MatrixXd Q = testing::random_matrix(kRows, j, 31);
  const Eigen::VectorXd x = testing::random_matrix(kRows, 1, 32);
  std::vector<double> s_baseline(j), s_wide(j);
  {
    testing::KernelEnv env("baseline");
    basis_coefficients(Q.data(), kRows, j, x.data(), nullptr, s_baseline.data(), nullptr, 1);
  }
  {
    testing::KernelEnv env("auto");
    basis_coefficients(Q.data(), kRows, j, x.data(), nullptr, s_wide.data(), nullptr, 1);
  }
  if (wide) EXPECT_NE(s_wide, s_baseline);
  else EXPECT_EQ(s_wide, s_baseline);
  for (long c = 0; c < j; ++c)
    EXPECT_NEAR(s_wide[c], s_baseline[c], dot_bound(Q.col(c), x));  // each within half of it of exact
}

TEST(GramSchmidt, ThreadsOnlyForLongVectors) {
  EXPECT_EQ(gram_schmidt_threads(1000), 1);
  EXPECT_EQ(gram_schmidt_threads((1L << 17) - 1), 1);
  EXPECT_GE(gram_schmidt_threads(1L << 24), 1);
  EXPECT_LE(gram_schmidt_threads(1L << 17), 2);
}

}  // namespace
}  // namespace delayspec::detail
