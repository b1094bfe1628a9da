// Floquet multipliers of a user-defined DDE with delayspec: a damped oscillator with delayed
// position feedback,  x'' + c x' + x = b x(t - tau),  y = (x, x'),  stroboscopic period T = tau.
#include <cstdio>
#include <delayspec/floquet.hpp>
#include <delayspec/stroboscopic_map.hpp>

struct DelayedOscillator {  // the model concept: see delayspec/model.hpp
  static constexpr int d = 2;
  static constexpr bool has_switching = false, affine_in_state = true, is_linear = true;
  using V = delayspec::Vec<2>;
  using M = delayspec::Mat<2>;
  double c = 0.1, b = -0.2, delay = 2.0;
  double tau() const { return delay; }
  double period() const { return delay; }
  M A(int, double, const V&, const V&) const { return (M() << 0, 1, -1, -c).finished(); }
  M B(int, double, const V&, const V&) const { return (M() << 0, 0, b, 0).finished(); }
  V f(int j, double t, const V& y, const V& y_tau) const { return A(j, t, y, y_tau) * y + B(j, t, y, y_tau) * y_tau; }
  double H(const V&) const { return 1; }
  V grad_H(const V&) const { return V::Zero(); }
  V initial_state() const { return V::Zero(); }
};

int main() {
  DelayedOscillator model;
  delayspec::HistoryGrid grid = delayspec::make_grid(model.tau(), model.period(), /*N=*/200);
  delayspec::TrapezoidStepper<DelayedOscillator> stepper(model);
  delayspec::StroboscopicMap<DelayedOscillator> map(stepper, grid);
  // A linear model: the monodromy does not depend on the orbit; linearise about zero.
  auto monodromy = map.monodromy(map.constant_history(model.initial_state()));
  auto result = delayspec::floquet_multipliers(monodromy, {.nev = 4, .solver = delayspec::FloquetSolver::dense_lapack});
  std::printf("leading Floquet multipliers (N = %d, n = %ld):\n", grid.N, map.dimension());
  for (auto mu : result.multipliers) std::printf("  %+.8f %+.8fi   |mu| = %.8f\n", mu.real(), mu.imag(), std::abs(mu));
  return result.multipliers.empty() ? 1 : 0;
}
