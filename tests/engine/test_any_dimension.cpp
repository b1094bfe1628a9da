// A model of a dimension the library is not compiled for (d = 3) goes through the whole engine:
// the operator, every Floquet backend, and Lyapunov exponents. Checked against an identity: three
// decoupled scalar DDEs x_i' = a_i x_i + b_i x_i(t - tau) discretise, component by component, to
// exactly the three scalar trapezoid maps (every block of the d = 3 step map is diagonal), so the
// d = 3 monodromy's spectrum is the union of the three d = 1 spectra (LinearModel, compiled in the
// library), to rounding.
#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include <gtest/gtest.h>

#include "delayspec/floquet.hpp"
#include "delayspec/lyapunov.hpp"
#include "delayspec/model_linear.hpp"
#include "delayspec/stroboscopic_map.hpp"

namespace delayspec {
namespace {

struct ThreeScalarDdes {
  static constexpr int d = 3;
  static constexpr bool has_switching = false, affine_in_state = true, is_linear = true;
  using V = Vec<3>;
  using M = Mat<3>;
  V a{-1.0, 0.3, -2.0}, b{0.5, -0.9, 1.7};
  double tau() const { return 1; }
  double period() const { return 1; }
  M A(int, double, const V&, const V&) const { return a.asDiagonal(); }
  M B(int, double, const V&, const V&) const { return b.asDiagonal(); }
  V f(int, double, const V& y, const V& y_tau) const { return a.cwiseProduct(y) + b.cwiseProduct(y_tau); }
  V initial_state() const { return V(1, 1, 1); }
};

// The model contract as a concept (model.hpp): switching members only when the model switches.
static_assert(DelayModel<ThreeScalarDdes>, "no H / grad_H needed without switching");
static_assert(DelayModel<LinearModel>);
struct SwitchingWithoutH : ThreeScalarDdes {
  static constexpr bool has_switching = true;  // then H, grad_H, f_t, f_tt are required
};
static_assert(!DelayModel<SwitchingWithoutH>);
struct TimeSwitchedWithoutSegments : ThreeScalarDdes {
  static constexpr bool has_time_switches = true;  // then time_segment, next_time_switch are
};
static_assert(!DelayModel<TimeSwitchedWithoutSegments>);

constexpr int kN = 60;

template <class Model>
Monodromy<Model::d> monodromy_of(const Model& model) {
  const StroboscopicMap<Model> map(TrapezoidStepper<Model>(model), make_grid(model.tau(), model.period(), kN));
  return map.monodromy(Eigen::VectorXd::Zero(map.dimension()));
}

// The union of the three scalar spectra, largest first.
Multipliers scalar_union(const ThreeScalarDdes& model, int per_component) {
  Multipliers all;
  for (int i = 0; i < 3; ++i) {
    const LinearModel scalar({.a = model.a[i], .b = model.b[i], .tau = 1, .period = 1});
    FloquetOptions o;
    o.nev = per_component;
    o.solver = FloquetSolver::dense_lapack;
    const Multipliers mu = floquet_multipliers(monodromy_of(scalar), o).multipliers;
    all.insert(all.end(), mu.begin(), mu.end());
  }
  sort_by_modulus(all);
  return all;
}

TEST(AnyDimension, EveryFloquetBackendOnADimensionThreeModel) {
  const ThreeScalarDdes model;
  const Monodromy<3> op = monodromy_of(model);
  ASSERT_EQ(op.rows(), 3 * (kN + 1));
  const int nev = 6;
  const Multipliers expected = scalar_union(model, nev);
  for (FloquetSolver solver : {FloquetSolver::dense_lapack, FloquetSolver::dense_eigen, FloquetSolver::spectra,
                               FloquetSolver::arpack, FloquetSolver::block}) {
    FloquetOptions o;
    o.nev = nev;
    o.solver = solver;
    const FloquetResult r = floquet_multipliers(op, o);
    ASSERT_EQ(r.multipliers.size(), static_cast<size_t>(nev)) << to_string(solver);
    // The same discrete spectrum; the backends' tolerance is 1e-12 relative (FloquetOptions) and
    // the dense ones are backward stable: 1e-10 of |mu_1| leaves room for clustered moduli.
    for (int k = 0; k < nev; ++k) {
      double nearest = INFINITY;
      for (const auto& e : expected) nearest = std::min(nearest, std::abs(r.multipliers[k] - e));
      EXPECT_LT(nearest, 1e-10 * std::abs(expected[0])) << to_string(solver) << " multiplier " << k + 1;
    }
  }
}

// Lyapunov exponents of a linear system are log |mu| / T of its leading multipliers; the run's
// own error estimate (batch means and fluctuation bound) is the tolerance, times 3.
TEST(AnyDimension, LyapunovOnADimensionThreeModel) {
  const ThreeScalarDdes model;
  const StroboscopicMap<ThreeScalarDdes> map(TrapezoidStepper<ThreeScalarDdes>(model),
                                             make_grid(model.tau(), model.period(), kN));
  LyapunovOptions o;
  o.exponents = 1;
  o.periods = 400;
  o.transient = 50;
  const LyapunovResult r = lyapunov_exponents(map, map.constant_history(model.initial_state()), o);
  const double expected = std::log(std::abs(scalar_union(model, 1)[0]));
  EXPECT_NEAR(r.per_period[0], expected, 3 * r.error_per_period[0] + 1e-12);
}

}  // namespace
}  // namespace delayspec
