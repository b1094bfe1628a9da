#pragma once
// The same branch from continuation's two correctors (ContinuationSolver), for the tests of
// test_condensed_bordered.cpp and test_hopf_branch.cpp.
#include <cmath>

#include <gtest/gtest.h>

#include "delayspec/continuation.hpp"

namespace delayspec::testing {

// The branches of one problem by both correctors: the same points (their count, parameters,
// multipliers) and bifurcations. (Not always the same iterations: where F is affine in x, as in
// free flight, the LU's first step is exact and GMRES' leaves the forcing term's residual, so the
// start may take one more; the step control counts <= 3 alike.) Tolerance 1e-9: each point solves
// F = 0 to |F|_inf <= 1e-12 (1 + |x|) on the same hyperplane, so two points differ by the
// condition of the bordered matrix times that (the tangents that set the hyperplanes are solved
// to 1e-12); a bifurcation is located to the options' tolerance (the callers': 1e-12, or 1e-10
// times a range of 10) from either. An orbit of unknown period: its period alike.
inline void expect_same_branch(const ContinuationResult& lu, const ContinuationResult& krylov) {
  EXPECT_EQ(lu.end, krylov.end);
  EXPECT_GT(lu.factorisations, 0);
  EXPECT_EQ(lu.gmres_products, 0);
  EXPECT_EQ(krylov.factorisations, 0);  // never a matrix factored
  EXPECT_GT(krylov.gmres_products, 0);
  ASSERT_EQ(lu.points.size(), krylov.points.size());
  for (size_t i = 0; i < lu.points.size(); ++i) {
    const ContinuationPoint &a = lu.points[i], &b = krylov.points[i];
    EXPECT_NEAR(a.parameter, b.parameter, 1e-9) << "point " << i;
    EXPECT_EQ(a.unstable, b.unstable) << "point " << i;
    if (!std::isnan(a.period)) {
      EXPECT_NEAR(a.period, b.period, 1e-9) << "point " << i;
    }
    ASSERT_EQ(a.multipliers.size(), b.multipliers.size()) << "point " << i;
    for (size_t j = 0; j < a.multipliers.size(); ++j)
      EXPECT_LE(std::abs(a.multipliers[j] - b.multipliers[j]), 1e-9) << "point " << i << ", multiplier " << j;
  }
  ASSERT_EQ(lu.bifurcations.size(), krylov.bifurcations.size());
  for (size_t i = 0; i < lu.bifurcations.size(); ++i) {
    EXPECT_EQ(lu.bifurcations[i].type, krylov.bifurcations[i].type);
    EXPECT_NEAR(lu.bifurcations[i].parameter, krylov.bifurcations[i].parameter, 1e-9) << lu.bifurcations[i].note;
  }
}

}  // namespace delayspec::testing
