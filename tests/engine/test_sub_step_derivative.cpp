// The factored derivative of a trapezoid sub-step (detail/sub_step_derivative.hpp), which the
// Lyapunov loop applies to its tangent vectors without forming P, Q, R:
//   * it equals the formed step map (P, Q, R through step_block) on random tangent blocks, to
//     the rounding bound of the two association orders;
//   * it is the derivative of the discrete sub-step: against central finite differences of z1
//     on a nonlinear d = 2 model whose A and B have no zero entry (so that a transposed, swapped
//     or mis-scaled block shows).
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "delayspec/detail/block_kernel.hpp"
#include "delayspec/model_impact.hpp"
#include "delayspec/model_mackey_glass.hpp"
#include "delayspec/model_mathieu.hpp"
#include "delayspec/stepper.hpp"

namespace delayspec {
namespace {

// x' = v + 0.3 sin(x) v_tau + cos t,  v' = -x - 0.2 v^3 + 0.5 x_tau v_tau + 0.1 x v_tau: not affine
// in the state (Newton iterates, S recomputed at z1), A and B dense and state dependent.
struct DenseNonlinear {
  static constexpr int d = 2;
  static constexpr bool has_switching = false, affine_in_state = false, is_linear = false;
  using V = Vec<2>;
  using M = Mat<2>;
  double tau() const { return 1; }
  double period() const { return 2 * std::numbers::pi; }
  V f(int, double t, const V& y, const V& w) const {
    return V(y[1] + 0.3 * std::sin(y[0]) * w[1] + std::cos(t),
             -y[0] - 0.2 * y[1] * y[1] * y[1] + 0.5 * w[0] * w[1] + 0.1 * y[0] * w[1]);
  }
  M A(int, double, const V& y, const V& w) const {
    M a;
    a << 0.3 * std::cos(y[0]) * w[1], 1, -1 + 0.1 * w[1], -0.6 * y[1] * y[1];
    return a;
  }
  M B(int, double, const V& y, const V& w) const {
    M b;
    b << 0, 0.3 * std::sin(y[0]), 0.5 * w[1], 0.5 * w[0] + 0.1 * y[0];
    return b;
  }
  V initial_state() const { return V(1, 0); }
};
static_assert(DelayModel<DenseNonlinear>);

constexpr double kEps = std::numeric_limits<double>::epsilon();

struct SubStepCase {
  double t0, dt;
  int region;  // left and right region (kRegionOfEndpoint: the plain step's choice)
};

template <int D>
Vec<D> random_vec(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Vec<D> v;
  for (int i = 0; i < D; ++i) v[i] = u(rng);
  return v;
}

// Applies the factored derivative (apply_factored_step<D, KC>) and the formed map (step_block)
// to the same k random interleaved vectors: current slot, delayed slots j - 1, j, j + 1. The
// two compute S^{-1} (L u + Bl w0 + Br w1) and (S^{-1} L) u + (S^{-1} Bl) w0 + (S^{-1} Br) w1:
// the same sums in another order, each entry within n eps of the exact value times its sum of
// absolute terms (n <= 4 D products and sums deep), so they differ by at most
//   8 D eps (|S^{-1}| (|L| |u| + |Bl| |w0| + |Br| |w1|))_r   (componentwise, |.| entrywise)
// for each component r; a wrong block would be O(1) of it.
template <class Model, int KC>
void expect_factored_equals_formed(const Model& model, const SubStepCase& c, long k, double theta, unsigned seed) {
  constexpr int D = Model::d;
  const TrapezoidStepper<Model> stepper(model);
  std::mt19937_64 rng(seed);
  const Vec<D> z0 = random_vec<D>(rng), w0 = random_vec<D>(rng), w1 = random_vec<D>(rng);
  detail::SubStepDerivative<D> derivative;
  int jr;
  stepper.factored_sub_step(c.t0, c.dt, z0, w0, w1, c.region == kRegionOfEndpoint ? region_of(model, z0) : c.region,
                            c.region, derivative, jr);
  const StepMap<D> map{derivative.dz0(), derivative.dw0(), derivative.dw1()};

  const long slot = static_cast<long>(D) * k;
  std::vector<double> u(slot), delayed(3 * slot), factored(slot), formed(slot);
  std::uniform_real_distribution<double> uniform(-1, 1);
  for (double& x : u) x = uniform(rng);
  for (double& x : delayed) x = uniform(rng);
  const double* d0 = delayed.data() + slot;  // slot j; j - 1 and j + 1 around it
  apply_factored_step<D, KC>(derivative, u.data(), d0, k, theta, factored.data());
  step_block<D, detail::PortableTarget, KC>(map, u.data(), d0, k, theta, formed.data());

  const Mat<D> abs_inverse = derivative.s.inverse().cwiseAbs();
  for (long v = 0; v < k; ++v) {
    Vec<D> au, aw0, aw1;  // |u|, |w0|, |w1| of vector v (interpolated with theta as the kernels do)
    for (int r = 0; r < D; ++r) {
      au[r] = std::abs(u[r * k + v]);
      aw0[r] = (1 - theta) * std::abs(d0[r * k + v]) + theta * std::abs(d0[r * k + v - slot]);
      aw1[r] = (1 - theta) * std::abs(d0[r * k + v + slot]) + theta * std::abs(d0[r * k + v]);
    }
    const Vec<D> scale = abs_inverse * (derivative.left.cwiseAbs() * au + derivative.bl.cwiseAbs() * aw0 +
                                        derivative.br.cwiseAbs() * aw1);
    for (int r = 0; r < D; ++r)
      EXPECT_NEAR(factored[r * k + v], formed[r * k + v], 8 * D * kEps * scale[r])
          << "component " << r << " of vector " << v << ", k = " << k << ", theta = " << theta;
  }
}

template <class Model>
void expect_factored_equals_formed_all_widths(const Model& model, const SubStepCase& c) {
  for (double theta : {0.0, 0.37}) {
    expect_factored_equals_formed<Model, 1>(model, c, 1, theta, 11);
    expect_factored_equals_formed<Model, 2>(model, c, 2, theta, 12);
    expect_factored_equals_formed<Model, 0>(model, c, 3, theta, 13);  // runtime k, one vector at a time
    expect_factored_equals_formed<Model, 0>(model, c, 8, theta, 14);
  }
}

TEST(SubStepDerivative, FactoredTangentsEqualTheFormedMapMathieu) {
  expect_factored_equals_formed_all_widths(MathieuModel(), {0.7, 2 * std::numbers::pi / 1000, kRegionOfEndpoint});
  // a coarse step: S far from I, so L, Bl, Br and S^{-1} all matter
  expect_factored_equals_formed_all_widths(MathieuModel(), {0.7, 0.8, kRegionOfEndpoint});
}

TEST(SubStepDerivative, FactoredTangentsEqualTheFormedMapImpactBothRegions) {
  ImpactParameters p;
  p.k = 0.2;
  const ImpactModel model(p);
  expect_factored_equals_formed_all_widths(model, {0.3, 0.05, 1});  // contact: A has beta in it
  expect_factored_equals_formed_all_widths(model, {0.3, 0.05, 2});
}

TEST(SubStepDerivative, FactoredTangentsEqualTheFormedMapScalarAndNonlinear) {
  expect_factored_equals_formed_all_widths(MackeyGlassModel(), {0.0, 0.3, kRegionOfEndpoint});
  expect_factored_equals_formed_all_widths(DenseNonlinear(), {0.4, 0.3, kRegionOfEndpoint});
}

// dz1 = S^{-1} [L dz0 + Bl dw0 + Br dw1] against the central difference of the discrete sub-step
// z1(z0 + e a, w0 + e b, w1 + e c) in random directions. Central differences of a smooth map
// err by e^2 |z1'''| / 6 (O(1) third derivatives here: ~2e-11 at e = 1e-5) plus rounding
// ~eps |z1| / e (~2e-11); the tolerance 1e-8 leaves a factor of 500 above both. A wrong
// derivative is off by far more: swapping Bl and Br, or evaluating S at the left node, changes
// it by O(dt |B_l - B_r| + dt^2 |A_l - A_r|), ~1e-2 at dt = 0.3 for this model.
TEST(SubStepDerivative, TangentIsTheDerivativeOfTheDiscreteStep) {
  const DenseNonlinear model;
  const TrapezoidStepper<DenseNonlinear> stepper(model);
  std::mt19937_64 rng(5);
  const double e = 1e-5;
  for (int trial = 0; trial < 20; ++trial) {
    const double t0 = 0.1 * trial, dt = 0.3;
    const Vec<2> z0 = random_vec<2>(rng), w0 = random_vec<2>(rng), w1 = random_vec<2>(rng);
    const Vec<2> a = random_vec<2>(rng), b = random_vec<2>(rng), c = random_vec<2>(rng);
    detail::SubStepDerivative<2> derivative;
    int jr;
    stepper.factored_sub_step(t0, dt, z0, w0, w1, 1, kRegionOfEndpoint, derivative, jr);
    auto z1 = [&](double s) { return stepper.sub_step_state(t0, dt, z0 + s * a, w0 + s * b, w1 + s * c, 1, 1); };
    const Vec<2> fd = (z1(e) - z1(-e)) / (2 * e);
    const Vec<2> tangent = derivative.apply(a, b, c);
    EXPECT_LE((tangent - fd).norm(), 1e-8 * (1 + fd.norm()))
        << "trial " << trial << ": tangent " << tangent.transpose() << ", finite difference " << fd.transpose();
    // The control: the same derivative with Bl and Br swapped is far outside the tolerance.
    detail::SubStepDerivative<2> swapped = derivative;
    std::swap(swapped.bl, swapped.br);
    EXPECT_GT((swapped.apply(a, b, c) - fd).norm(), 1e-4 * (1 + fd.norm())) << "trial " << trial;
  }
}

}  // namespace
}  // namespace delayspec
