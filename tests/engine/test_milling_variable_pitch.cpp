// Variable-pitch milling (model_milling_variable_pitch.hpp):
// - all angles equal is the equal-pitch model: the same multipliers to rounding;
// - an unequal pitch (4 teeth, 80/100/80/100 degrees: two delays) against a zeroth-order
//   semi-discretisation with several delays written here (Insperger & Stepan's method, which
//   shares no code with delayspec's step): each converges at its own order 2 and both tend to the
//   same leading multiplier, within their extrapolations' error estimates;
// - bad pitch angles are BadInput naming them.
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <vector>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>
#include <gtest/gtest.h>

#include "delayspec/errors.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/model_milling.hpp"
#include "delayspec/model_milling_variable_pitch.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec {
namespace {

MillingParameters tool(std::vector<double> pitch_angles) {
  MillingParameters p;
  p.teeth = static_cast<int>(pitch_angles.size());
  p.pitch_angles = std::move(pitch_angles);
  p.radial_immersion = 0.5;
  p.spindle_rpm = 10000;
  p.depth = 1e-3;
  return p;
}

template <class Model>
std::vector<std::complex<double>> leading(const Model& model, int N, int nev = 4) {
  const StroboscopicMap<Model> map(TrapezoidStepper<Model>(model), make_grid(delays_of(model), model.period(), N));
  FloquetOptions fo;
  fo.nev = nev;
  fo.solver = FloquetSolver::spectra;
  return floquet_multipliers(map.monodromy(Eigen::VectorXd::Zero(map.dimension())), fo).multipliers;
}

TEST(VariablePitchMilling, EqualAnglesAreTheEqualPitchModel) {
  MillingParameters equal = tool({90, 90, 90, 90});
  const VariablePitchMillingModel variable(equal);
  EXPECT_EQ(variable.distinct_pitches(), 1);
  equal.pitch_angles.clear();
  const MillingModel model(equal);
  // One tooth period, one delay of that length (the three padded slots have zero gain).
  EXPECT_NEAR(variable.period(), model.period(), 1e-15 * model.period());
  EXPECT_NEAR(variable.tau(), model.tau(), 1e-15 * model.tau());
  const auto a = leading(variable, 200), b = leading(model, 200);
  // The same grid and the same steps up to the rounding of the period (an ulp) and of the sum
  // over padded zero-gain slots: the Krylov multipliers agree to its residual level, 1e-12.
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) EXPECT_LE(std::abs(a[k] - b[k]), 1e-12 * std::abs(b[0])) << k;
}

// Zeroth-order semi-discretisation (Insperger & Stepan, Int. J. Numer. Meth. Eng. 55, 2002), with
// several delays, from the milling equation itself (not the model's coefficients): tooth j at
// phi_j = Omega t + psi_0 + ... + psi_{j-1}, in the cut for phi_st <= phi_j mod 2 pi < phi_ex
// (down-milling, phi_st = arccos(2 a/D - 1), phi_ex = pi), cutting what tooth j + 1 left psi_j /
// Omega before. m steps of dt over the period T (half a revolution here); the delay of spacing
// psi is r dt exactly (the test's pitch is chosen so). On [t_i, t_{i+1}] the coefficients are
// their means (midpoint rule, 40 points) and each delayed position the mean of its two nodes; the
// ODE is solved exactly:
//   z_{i+1} = e^{A_i dt} z_i + G_i sum_j c_{j,i} (x_{i - r_j + 1} + x_{i - r_j}) / 2,
//   G_i = int_0^dt e^{A_i s} ds e_2,  c_j = (a_p / m) g_j sin(phi_j) (K_t cos(phi_j) + K_n sin(phi_j)).
// The state (z_i, x_{i-1}, ..., x_{i-r}) has n = 2 + r entries, r = max r_j; its monodromy is
// formed column by column with the shift structure. Returns the leading multiplier's modulus.
double semi_discretised_leading_modulus(const MillingParameters& p, double T, int m) {
  const double dt = T / m, Omega = 2 * std::numbers::pi * p.spindle_rpm / 60;
  const double phi_st = std::acos(2 * p.radial_immersion - 1), phi_ex = std::numbers::pi;
  const double w = p.omega_n, cut = p.depth / p.mass;
  std::vector<double> offset(p.teeth, 0.0);
  std::vector<int> lag(p.teeth);
  for (int j = 0; j < p.teeth; ++j) {
    if (j > 0) offset[j] = offset[j - 1] + p.pitch_angles[j - 1] * std::numbers::pi / 180;
    lag[j] = static_cast<int>(std::lround(p.pitch_angles[j] * std::numbers::pi / 180 / Omega / dt));
  }
  const int rmax = *std::max_element(lag.begin(), lag.end());
  const int n = 2 + rmax;
  Eigen::MatrixXd Phi = Eigen::MatrixXd::Identity(n, n);
  for (int i = 0; i < m; ++i) {
    Eigen::Matrix2d A;
    A << 0, 1, -w * w, -2 * p.zeta * w;
    std::vector<double> c(p.teeth, 0.0);
    constexpr int kPoints = 40;
    for (int q = 0; q < kPoints; ++q) {
      const double t = (i + (q + 0.5) / kPoints) * dt;
      for (int j = 0; j < p.teeth; ++j) {
        const double phi = Omega * t + offset[j];
        const double wrapped = phi - 2 * std::numbers::pi * std::floor(phi / (2 * std::numbers::pi));
        if (wrapped < phi_st || wrapped >= phi_ex) continue;
        const double h = std::sin(phi) * (p.Kt * std::cos(phi) + p.Kn * std::sin(phi));
        c[j] += cut * h / kPoints;
        A(1, 0) -= cut * h / kPoints;
      }
    }
    Eigen::Matrix3d augmented = Eigen::Matrix3d::Zero();  // [[A, e_2], [0, 0]] dt
    augmented.topLeftCorner<2, 2>() = A * dt;
    augmented(1, 2) = dt;
    const Eigen::Matrix3d E = augmented.exp();  // [[e^{A dt}, G], [0, 1]] (Van Loan)
    const Eigen::Matrix2d S = E.topLeftCorner<2, 2>();
    const Eigen::Vector2d G = E.topRightCorner<2, 1>();
    Eigen::MatrixXd next(n, Phi.cols());
    for (int col_index = 0; col_index < Phi.cols(); ++col_index) {
      const auto col = Phi.col(col_index);
      // slot s >= 1 of the state holds x_{i-s}; slot 0 of z is x_i.
      const auto x_at = [&](int s) { return s == 0 ? col(0) : col(1 + s); };
      double force = 0;
      for (int j = 0; j < p.teeth; ++j) force += c[j] * (x_at(lag[j] - 1) + x_at(lag[j])) / 2;
      next.col(col_index).head<2>() = S * col.head<2>() + G * force;
      next(2, col_index) = col(0);                                        // x_i becomes x_{(i+1)-1}
      next.col(col_index).tail(rmax - 1) = col.segment(2, rmax - 1);       // the rest shifted by one
    }
    Phi = next;
  }
  return Phi.eigenvalues().cwiseAbs().maxCoeff();
}

TEST(VariablePitchMilling, AnUnequalPitchMeetsAnIndependentSemiDiscretisation) {
  const VariablePitchMillingModel model(tool({80, 100, 80, 100}));
  EXPECT_EQ(model.distinct_pitches(), 2);
  // Alternating pitch: the pattern repeats after half a revolution, and the delays are 80 and 100
  // degrees of it, 4/9 and 5/9 of the period.
  const double revolution = 60 / model.parameters().spindle_rpm;
  EXPECT_NEAR(model.period(), revolution / 2, 1e-15 * revolution);
  EXPECT_NEAR(model.delays()[0], revolution * 80 / 360, 1e-15 * revolution);
  EXPECT_NEAR(model.delays()[1], revolution * 100 / 360, 1e-15 * revolution);

  // delayspec: N steps per the longest delay (N = 100 .. 800, aligned: N 9/5 steps per period).
  std::vector<double> ours;
  for (int N : {100, 200, 400, 800}) ours.push_back(std::abs(leading(model, N)[0]));
  // The semi-discretisation: m = 90 .. 720 steps per half revolution (r = 4m/9 and 5m/9 exact).
  std::vector<double> theirs;
  const double half_revolution = revolution / 2;
  for (int m : {90, 180, 360, 720}) theirs.push_back(semi_discretised_leading_modulus(model.parameters(), half_revolution, m));

  // Each converges at order 2 (halving the step quarters the difference: band 2 +- 0.25, the
  // finest pairs' order, where h^2 dominates), and Richardson's extrapolation of the two finest
  // levels carries the error estimate |extrapolation(finest pair) - extrapolation(previous pair)|.
  struct Study {
    double order, limit, error;
  };
  const auto study = [](const std::vector<double>& v) {
    const double d1 = v[2] - v[1], d2 = v[3] - v[2];
    const double limit = v[3] + d2 / 3, previous = v[2] + d1 / 3;
    return Study{std::log2(std::abs(d1 / d2)), limit, std::abs(limit - previous)};
  };
  const Study a = study(ours), b = study(theirs);
  std::printf("80/100/80/100: delayspec |mu_1| %.10f +- %.1e (order %.2f), semi-discretisation %.10f +- %.1e (order %.2f)\n",
              a.limit, a.error, a.order, b.limit, b.error, b.order);
  EXPECT_NEAR(a.order, 2.0, 0.25) << ours[0] << " " << ours[1] << " " << ours[2] << " " << ours[3];
  EXPECT_NEAR(b.order, 2.0, 0.25) << theirs[0] << " " << theirs[1] << " " << theirs[2] << " " << theirs[3];
  // Two discretisations of one equation: the same limit, within their estimates (three times
  // their sum, the usual margin of an estimate of the next term).
  EXPECT_LE(std::abs(a.limit - b.limit), 3 * (a.error + b.error))
      << "delayspec " << a.limit << " +- " << a.error << ", semi-discretisation " << b.limit << " +- " << b.error;
  // And the estimates are small against what is compared: the leading multiplier to 1e-5 or better.
  EXPECT_LT(a.error + b.error, 1e-5 * a.limit);
}

TEST(VariablePitchMilling, BadPitchAnglesAreBadInputNamingThem) {
  const auto message = [](MillingParameters p) {
    try {
      VariablePitchMillingModel model(p);
    } catch (const BadInput& e) {
      return std::string(e.what());
    }
    return std::string("no BadInput");
  };
  MillingParameters p = tool({90, 90, 90, 80});
  EXPECT_NE(message(p).find("sum to 350"), std::string::npos) << message(p);
  p = tool({90, 90, 180});
  p.teeth = 4;
  EXPECT_NE(message(p).find("3 angles for `teeth = 4`"), std::string::npos) << message(p);
  p = tool({-10, 190, 90, 90});
  EXPECT_NE(message(p).find("must be > 0"), std::string::npos) << message(p);
  p = tool({50, 60, 70, 80, 100});
  EXPECT_NE(message(p).find("more than 4 distinct spacings"), std::string::npos) << message(p);
}

}  // namespace
}  // namespace delayspec
