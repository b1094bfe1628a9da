// Discretisation order against exact values the code did not produce:
//  * linear DDE x' = a x + b x(t - tau): multipliers exp(lambda T), lambda from Lambert W;
//  * delayed Mathieu equation: the spectral radius 0.512052284098 quoted in issue 2.
// The trapezoidal rule is second order, so the error of a simple leading multiplier is
// C h^2 + O(h^4) and log2(e_N / e_2N) -> 2; over N = 20 ... 640 the O(h^4) term moves the
// ratio by less than 0.1 on these smooth problems.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "delayspec/lambert_w.hpp"
#include "delayspec/model_linear.hpp"
#include "delayspec/model_mathieu.hpp"
#include "test_support.hpp"

using namespace delayspec;
using namespace delayspec::testing;

namespace {

struct LinearCase {
  const char* name;
  double a, b, tau, period;
};

void PrintTo(const LinearCase& c, std::ostream* os) { *os << c.name; }

class LinearLeadingMultiplier : public ::testing::TestWithParam<LinearCase> {};

}  // namespace

TEST_P(LinearLeadingMultiplier, ConvergesAtSecondOrderToLambertW) {
  const LinearCase c = GetParam();
  const LinearModel model({.a = c.a, .b = c.b, .tau = c.tau, .period = c.period});
  const auto exact = linear_dde_multipliers(c.a, c.b, c.tau, c.period, 1);
  const std::complex<double> mu = exact[0];
  std::vector<double> errors;
  for (int N = 20; N <= 640; N *= 2) {
    const auto computed = dense_multipliers(model, N, 4);
    errors.push_back(distance_to_nearest(computed, mu) / std::abs(mu));
  }
  for (size_t i = 0; i + 1 < errors.size(); ++i) {
    const double order = std::log2(errors[i] / errors[i + 1]);
    EXPECT_GE(order, 1.9) << c.name << " N = " << (20 << i) << " errors " << errors[i] << " " << errors[i + 1];
    EXPECT_LE(order, 2.1) << c.name << " N = " << (20 << i) << " errors " << errors[i] << " " << errors[i + 1];
  }
  // error <= C h^2 with one C for the whole range: e_N N^2 varies by less than 20 %.
  const double c0 = errors.front() * 20 * 20;
  for (size_t i = 0; i < errors.size(); ++i) {
    const double N = 20 << i;
    EXPECT_NEAR(errors[i] * N * N, c0, 0.2 * c0) << c.name << " N = " << N;
  }
}

INSTANTIATE_TEST_SUITE_P(TauEqualsT_T2_2T, LinearLeadingMultiplier,
                         ::testing::Values(LinearCase{"stable_tau_T", -1.0, 0.5, 1.0, 1.0},   // real root -0.4, mu < 1
                                           LinearCase{"unstable_tau_T", 0.2, 0.3, 1.0, 1.0},  // real root > 0, mu > 1
                                           LinearCase{"oscillatory_tau_T", -1.0, -2.0, 1.0, 1.0},  // complex pair leads
                                           LinearCase{"stable_tau_T2", -1.0, 0.5, 1.0, 2.0},       // tau = T/2
                                           LinearCase{"unstable_tau_T2", 0.2, 0.3, 1.0, 2.0},
                                           LinearCase{"oscillatory_tau_T2", -1.0, -2.0, 1.0, 2.0},
                                           LinearCase{"stable_tau_2T", -1.0, 0.5, 1.0, 0.5},  // tau = 2T
                                           LinearCase{"unstable_tau_2T", 0.2, 0.3, 1.0, 0.5},
                                           LinearCase{"oscillatory_tau_2T", -1.0, -2.0, 1.0, 0.5}),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(MathieuSpectralRadius, ConvergesAtSecondOrder) {
  // kappa = 0.1, delta = 3, eps = 2, b = -0.15 (issue 2): rho = 0.512052284098 (12 digits).
  const double rho = 0.512052284098;
  const MathieuModel model({.kappa = 0.1, .delta = 3, .eps = 2, .b = -0.15});
  std::vector<double> errors, radii;
  for (int N = 25; N <= 400; N *= 2) {
    radii.push_back(std::abs(dense_multipliers(model, N, 1)[0]));
    errors.push_back(std::abs(radii.back() - rho));
  }
  for (size_t i = 0; i + 1 < errors.size(); ++i) {
    const double order = std::log2(errors[i] / errors[i + 1]);
    EXPECT_GE(order, 1.9) << "N = " << (25 << i) << ": " << errors[i] << " -> " << errors[i + 1];
    EXPECT_LE(order, 2.1) << "N = " << (25 << i) << ": " << errors[i] << " -> " << errors[i + 1];
  }
  // Richardson on the last two levels removes the h^2 term; what remains is O(h^4), about
  // (e_400)^2 / C ~ 1e-7 here: the limit of the discretisation is the published value.
  const double extrapolated = (4 * radii[radii.size() - 1] - radii[radii.size() - 2]) / 3;
  EXPECT_NEAR(extrapolated, rho, 1e-6) << "extrapolated " << extrapolated;
  std::printf("rho(N=400) = %.12f error %.3e; extrapolated %.12f error %.3e\n", radii.back(), errors.back(),
              extrapolated, std::abs(extrapolated - rho));
}
