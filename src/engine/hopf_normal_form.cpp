// The first Lyapunov coefficient of a Hopf point: the math is in hopf_normal_form.hpp.
#include "delayspec/hopf_normal_form.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SVD>

#include "delayspec/errors.hpp"

namespace delayspec {

std::string to_string(HopfCriticality c) {
  switch (c) {
    case HopfCriticality::supercritical: return "supercritical";
    case HopfCriticality::subcritical: return "subcritical";
    case HopfCriticality::degenerate: return "degenerate";
  }
  return "degenerate";
}

namespace {

using cd = std::complex<double>;
constexpr double kEps = std::numeric_limits<double>::epsilon();

// The second and third derivatives of f at X as J's first and second directional derivatives,
// by the fourth-order central stencils
//   DJ[u]     ~ (8 (J(X + h u) - J(X - h u)) - (J(X + 2h u) - J(X - 2h u))) / (12 h),
//   D^2J[u,u] ~ (-J(X + 2h u) + 16 J(X + h u) - 30 J(X) + 16 J(X - h u) - J(X - 2h u)) / (12 h^2),
// h = s (1 + |X|_inf) / |u|_inf: relative to the state's size, whatever the direction's.
class Derivatives {
 public:
  Derivatives(const JacobianAt& jacobian, const Eigen::VectorXd& X, long d, double s)
      : jacobian_(jacobian), X_(X), d_(d), s_(s), J0_(at(Eigen::VectorXd::Zero(X.size()), 0)) {}

  // B(U, V) = DJ[U] V, complex U by linearity
  Eigen::VectorXcd B(const Eigen::VectorXcd& U, const Eigen::VectorXcd& V) const {
    return first(U.real()).cast<cd>() * V + cd(0, 1) * (first(U.imag()).cast<cd>() * V);
  }
  // C(U, U, V) = D^2J[U, U] V: D^2J[a + i b, a + i b] = D^2J[a, a] - D^2J[b, b] + 2 i D^2J[a, b],
  // D^2J[a, b] = (D^2J[a + b, a + b] - D^2J[a - b, a - b]) / 4
  Eigen::VectorXcd C(const Eigen::VectorXcd& U, const Eigen::VectorXcd& V) const {
    const Eigen::VectorXd a = U.real(), b = U.imag();
    const Eigen::MatrixXd mixed = (second(a + b) - second(a - b)) / 4;
    return (second(a) - second(b)).cast<cd>() * V + cd(0, 2) * (mixed.cast<cd>() * V);
  }

 private:
  Eigen::MatrixXd at(const Eigen::VectorXd& u, double t) const {
    const Eigen::VectorXd x = X_ + t * u;
    return jacobian_(x.head(d_), x.tail(x.size() - d_));
  }
  double step(const Eigen::VectorXd& u) const { return s_ * (1 + X_.cwiseAbs().maxCoeff()) / u.cwiseAbs().maxCoeff(); }
  Eigen::MatrixXd first(const Eigen::VectorXd& u) const {
    if (u.cwiseAbs().maxCoeff() == 0) return Eigen::MatrixXd::Zero(J0_.rows(), J0_.cols());
    const double h = step(u);
    return (8 * (at(u, h) - at(u, -h)) - (at(u, 2 * h) - at(u, -2 * h))) / (12 * h);
  }
  Eigen::MatrixXd second(const Eigen::VectorXd& u) const {
    if (u.cwiseAbs().maxCoeff() == 0) return Eigen::MatrixXd::Zero(J0_.rows(), J0_.cols());
    const double h = step(u);
    return (16 * (at(u, h) + at(u, -h)) - (at(u, 2 * h) + at(u, -2 * h)) - 30 * J0_) / (12 * h * h);
  }

  const JacobianAt& jacobian_;
  Eigen::VectorXd X_;
  long d_;
  double s_;
  Eigen::MatrixXd J0_;
};

// A point where the normal form does not exist: why.
struct Degenerate {
  std::string why;
};

// The critical modes at lambda = i omega: v right (|v| = 1, largest entry real > 0) and u left
// with u^H Delta' v = 1, the singular vectors of Delta's least singular value.
struct Modes {
  Eigen::VectorXcd v, u;
};

Modes critical_modes(const ConstantHistory& h, double omega) {
  Eigen::MatrixXcd derivative;
  const Eigen::MatrixXcd delta = h.delta(cd(0, omega), &derivative);
  const long d = delta.rows();
  const Eigen::JacobiSVD<Eigen::MatrixXcd> svd(delta, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Modes m{svd.matrixV().col(d - 1), svd.matrixU().col(d - 1)};
  Eigen::Index largest = 0;
  m.v.cwiseAbs().maxCoeff(&largest);
  m.v *= std::abs(m.v[largest]) / m.v[largest];
  const cd k = m.u.dot(derivative * m.v);  // u^H Delta' v
  if (std::abs(k) <= 1e3 * kEps * derivative.norm())
    throw Degenerate{"u^H Delta'(i omega) v = 0: the root i omega is not simple"};
  m.u /= std::conj(k);
  return m;
}

// (x, x e^{-k i omega tau_1}, ..., x e^{-k i omega tau_n}): a mode x e^{k i omega theta} at the
// delayed arguments
Eigen::VectorXcd stacked(const Eigen::VectorXcd& x, const std::vector<double>& taus, double k_omega) {
  const long d = x.size();
  Eigen::VectorXcd out(d * static_cast<long>(taus.size() + 1));
  out.head(d) = x;
  for (size_t i = 0; i < taus.size(); ++i) out.segment(d * static_cast<long>(i + 1), d) = x * std::exp(cd(0, -k_omega * taus[i]));
  return out;
}

// Delta(lambda)^{-1} b, Degenerate where Delta(lambda) is singular to rounding
Eigen::VectorXcd solved(const ConstantHistory& h, cd lambda, const Eigen::VectorXcd& b, const char* what) {
  const Eigen::MatrixXcd delta = h.delta(lambda);
  const Eigen::JacobiSVD<Eigen::MatrixXcd> svd(delta, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd sigma = svd.singularValues();
  if (!(sigma(sigma.size() - 1) > 1e3 * kEps * sigma(0)))
    throw Degenerate{std::string(what) + " is singular to rounding"};
  return svd.solve(b);
}

// c1 with the derivatives at relative step s and the modes at omega, and the size of its terms
// (1/2 |u| (|C| + |B(H20, .)| + 2 |B(H11, .)|): what rounding in the sum is relative to)
struct Coefficient {
  cd c1;
  double scale = 0;
};

Coefficient first_coefficient(const JacobianAt& jacobian, const ConstantHistory& h, const Eigen::VectorXd& y, double omega,
                     double s) {
  const long d = y.size();
  Eigen::VectorXd X(d * static_cast<long>(h.taus.size() + 1));
  for (long i = 0; i < X.size(); i += d) X.segment(i, d) = y;
  const Derivatives D(jacobian, X, d, s);
  const Modes m = critical_modes(h, omega);
  const Eigen::VectorXcd Phi = stacked(m.v, h.taus, omega), Phi_bar = Phi.conjugate();
  const Eigen::VectorXcd h20 = solved(h, cd(0, 2 * omega), D.B(Phi, Phi), "Delta(2 i omega) (a 1:2 resonance of roots)");
  const Eigen::VectorXcd h11 = solved(h, 0, D.B(Phi, Phi_bar), "Delta(0) (a zero root beside the pair: a zero-Hopf point)");
  const Eigen::VectorXcd cubic = D.C(Phi, Phi_bar), from_h20 = D.B(stacked(h20, h.taus, 2 * omega), Phi_bar),
                        from_h11 = 2.0 * D.B(stacked(h11, h.taus, 0), Phi);
  return {0.5 * m.u.dot(cubic + from_h20 + from_h11),
          0.5 * m.u.norm() * (cubic.norm() + from_h20.norm() + from_h11.norm())};
}

// The Jacobian with every entry's last bits disturbed, J_ij (1 + 4 eps xi), xi uniform in [-1, 1]
// from a fixed seed: c1 computed through it minus c1 samples what the rounding of the model's J
// does to c1 through the stencils (amplified by 1 / h^2), which the differences between steps
// may hide where they agree by chance.
JacobianAt disturbed(const JacobianAt& jacobian, unsigned seed) {
  return [&jacobian, generator = std::make_shared<std::minstd_rand>(seed)](const Eigen::VectorXd& y,
                                                                             const Eigen::VectorXd& w) {
    Eigen::MatrixXd J = jacobian(y, w);
    std::uniform_real_distribution<double> xi(-1, 1);
    for (Eigen::Index i = 0; i < J.size(); ++i) J.data()[i] *= 1 + 4 * kEps * xi(*generator);
    return J;
  };
}

}  // namespace

HopfNormalForm hopf_normal_form(const JacobianAt& jacobian, const ConstantHistory& at_equilibrium,
                                const Eigen::VectorXd& y, const CharacteristicRoot& root) {
  HopfNormalForm out;
  const double omega = root.value.imag();
  if (!(omega > 0)) throw BadInput("hopf_normal_form: the critical root must have Im > 0");
  try {
    out.eigenvector = critical_modes(at_equilibrium, omega).v;
    // Ridders' extrapolation in the difference step (header comment): T(k, 0) = c1 at s_k,
    // T(k, j) = (2^{2j+2} T(k, j-1) - T(k-1, j-1)) / (2^{2j+2} - 1) removes the s^{2j+2} term
    constexpr int kSteps = 12, kColumns = 4;
    std::array<std::array<cd, kColumns>, kSteps> T{};
    double bound = std::numeric_limits<double>::infinity(), best_step = 0, best_scale = 0;
    for (int k = 0; k < kSteps; ++k) {
      const double s = 0.1 / std::ldexp(1.0, k);
      const Coefficient c = first_coefficient(jacobian, at_equilibrium, y, omega, s);
      T[k][0] = c.c1;
      // the rounding of J through the stencils at this step: two samples (disturbed())
      double rounding = 0;
      for (unsigned seed : {1u, 2u})
        rounding = std::max(
            rounding, std::abs(first_coefficient(disturbed(jacobian, seed), at_equilibrium, y, omega, s).c1 - c.c1));
      for (int j = 1; j <= std::min(k, kColumns - 1); ++j) {
        const double f = std::ldexp(1.0, 2 * j + 2);
        T[k][j] = (f * T[k][j - 1] - T[k - 1][j - 1]) / (f - 1);
        // its error: how far it is from the two entries it came from and from the entry of its
        // column one step coarser, and the rounding
        double e = std::max(std::abs(T[k][j] - T[k][j - 1]), std::abs(T[k][j] - T[k - 1][j - 1]));
        if (j < k) e = std::max(e, std::abs(T[k][j] - T[k - 1][j]));
        e = 2 * (e + rounding) / omega;
        if (e < bound) bound = e, out.c1 = T[k][j], best_step = s, best_scale = c.scale;
      }
    }
    out.l1 = out.c1.real() / omega;
    out.difference_step = best_step;
    // the root's part: l1's slope in omega (a difference at a step far above the root's error,
    // the same stencils) times how far the root may be from i omega*
    const double off_axis = std::abs(root.value.real()) + root.error_bound;
    const double eta = 1e-6 * (1 + omega);
    const double slope =
        std::abs(first_coefficient(jacobian, at_equilibrium, y, omega + eta, best_step).c1.real() / (omega + eta) -
                 first_coefficient(jacobian, at_equilibrium, y, omega, best_step).c1.real() / omega) /
        eta;
    // never below the rounding of the sum of c1's terms (they may cancel: l1 near 0)
    out.l1_bound = std::max(bound + slope * off_axis, 16 * kEps * best_scale / omega);
    if (!std::isfinite(out.l1) || !std::isfinite(out.l1_bound))
      throw Degenerate{"the differences of the Jacobian are not finite (the model is not smooth there)"};
    out.criticality = out.l1 + out.l1_bound < 0   ? HopfCriticality::supercritical
                      : out.l1 - out.l1_bound > 0 ? HopfCriticality::subcritical
                                                  : HopfCriticality::degenerate;
  } catch (const Degenerate& e) {
    out.l1 = std::numeric_limits<double>::quiet_NaN();
    out.l1_bound = std::numeric_limits<double>::infinity();
    out.criticality = HopfCriticality::degenerate;
    out.note = "no first Lyapunov coefficient: " + e.why;
  }
  return out;
}

}  // namespace delayspec
