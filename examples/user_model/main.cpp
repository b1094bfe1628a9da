// Floquet multipliers of a user-defined DDE of dimension 3 with delayspec (the library is
// compiled for d = 1 and 2; any other d is instantiated here from the installed headers):
// a damped oscillator whose delayed feedback acts through a first-order filter z,
//
//   x'' + c x' + x = b z(t - tau),   z' = (x - z) / T_f,   y = (x, x', z),   period T = tau.
//
// The leading multipliers by ARPACK (matrix-free) and by the dense reference must agree.
#include <cmath>
#include <cstdio>
#include <delayspec/floquet.hpp>
#include <delayspec/stroboscopic_map.hpp>

struct FilteredDelayedOscillator {  // the model concept: see delayspec/model.hpp
  static constexpr int d = 3;
  static constexpr bool has_switching = false, affine_in_state = true, is_linear = true;
  using V = delayspec::Vec<3>;
  using M = delayspec::Mat<3>;
  double c = 0.1, b = -0.2, filter = 0.5, delay = 2.0;
  double tau() const { return delay; }
  double period() const { return delay; }
  M A(int, double, const V&, const V&) const {
    return (M() << 0, 1, 0, -1, -c, 0, 1 / filter, 0, -1 / filter).finished();
  }
  M B(int, double, const V&, const V&) const { return (M() << 0, 0, 0, 0, 0, b, 0, 0, 0).finished(); }
  V f(int j, double t, const V& y, const V& y_tau) const { return A(j, t, y, y_tau) * y + B(j, t, y, y_tau) * y_tau; }
  V initial_state() const { return V::Zero(); }
};

int main() {
  FilteredDelayedOscillator model;
  delayspec::HistoryGrid grid = delayspec::make_grid(model.tau(), model.period(), /*N=*/200);
  delayspec::TrapezoidStepper<FilteredDelayedOscillator> stepper(model);
  delayspec::StroboscopicMap<FilteredDelayedOscillator> map(stepper, grid);
  // A linear model: the monodromy does not depend on the orbit; linearise about zero.
  auto monodromy = map.monodromy(map.constant_history(model.initial_state()));
  auto krylov = delayspec::floquet_multipliers(monodromy, {.nev = 4, .solver = delayspec::FloquetSolver::arpack});
  auto dense = delayspec::floquet_multipliers(monodromy, {.nev = 4, .solver = delayspec::FloquetSolver::dense_lapack});
  std::printf("leading Floquet multipliers (d = 3, N = %d, n = %ld), ARPACK and dense LAPACK:\n", grid.N,
              map.dimension());
  double worst = 0;
  for (size_t k = 0; k < krylov.multipliers.size(); ++k) {
    const auto mu = krylov.multipliers[k];
    double nearest = INFINITY;  // a conjugate pair may come in either order
    for (auto nu : dense.multipliers) nearest = std::min(nearest, std::abs(mu - nu));
    worst = std::max(worst, nearest);
    std::printf("  %+.10f %+.10fi   |mu| = %.10f\n", mu.real(), mu.imag(), std::abs(mu));
  }
  std::printf("largest difference to the dense reference: %.1e\n", worst);
  // ARPACK's tolerance is 1e-12 relative (FloquetOptions): 1e-9 of |mu_1| is a clear failure.
  return worst <= 1e-9 * std::abs(dense.multipliers[0]) ? 0 : 1;
}
