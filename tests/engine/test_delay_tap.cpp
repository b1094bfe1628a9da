// HistoryGrid::delay_tap, the one statement of "the delayed values at a step's two ends and the
// step's time", against the formulas it replaced at its five call sites (stroboscopic_map.hpp,
// simulation.hpp, lyapunov.hpp, orbit_newton.hpp, monodromy.cpp), written out literally here,
// on an aligned and a fractional delay. The replacement must not change one bit: the same
// operations in the same order, so every comparison is exact (EXPECT_EQ, no tolerance), except
// the monodromy's (same_to_rounding below says why).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "delayspec/grid.hpp"
#include "delayspec/model_impact.hpp"
#include "delayspec/model_mackey_glass.hpp"
#include "delayspec/model_mathieu.hpp"
#include "delayspec/stroboscopic_map.hpp"

using namespace delayspec;

namespace {

// Aligned: tau = T (theta = 0). Fractional: tau / T = 1 / sqrt(2), irrational (theta in (0, 1)).
HistoryGrid aligned_grid() { return make_grid(1.0, 1.0, 12); }
HistoryGrid fractional_grid() { return make_grid(1.0, std::sqrt(2.0), 12); }

bool same_bits(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && (a.array() == b.array()).all();
}

// The monodromy is the exception to "not one bit": since issue 17 (item 5) it runs its own
// kernels (block_kernel.hpp), which apply the same tap but add Q w0 + R w1 before P u0 (u0 is
// the recurrence, kept off the front of the sum), so it agrees with the old loop to rounding: a
// few eps per step over the K = 12-17 steps of these grids, maps of norm ~1, far below 1e-13 relative.
// tests/engine/test_kernel_dispatch.cpp checks every kernel path against delay_tap the same way.
bool same_to_rounding(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && (a - b).norm() <= 1e-13 * b.norm();
}

// The loop StroboscopicMap::apply ran before delay_tap, verbatim but for the names.
template <class Model>
Eigen::VectorXd old_map_apply(const StroboscopicMap<Model>& map, const Eigen::VectorXd& U,
                              std::vector<StepMap<Model::d>>* maps = nullptr) {
  using V = Vec<Model::d>;
  constexpr int D = Model::d;
  const HistoryGrid& grid = map.grid();
  const long M = grid.M, m = grid.m, K = grid.K;
  const double theta = grid.theta, c0 = 1 - theta, h = grid.h;
  std::vector<V> b(static_cast<size_t>(M + 1 + K));
  for (long j = 0; j <= M; ++j) b[j] = U.segment<D>(j * D);
  if (maps) maps->resize(K);
  StepMap<D> scratch;
  for (long l = 0; l < K; ++l) {
    const long j = M + l - m;
    V w0 = theta == 0 ? b[j] : V(c0 * b[j] + theta * b[j - 1]);
    V w1 = theta == 0 ? b[j + 1] : V(c0 * b[j + 1] + theta * b[j]);
    double t = static_cast<double>(l % grid.steps_per_period) * h;
    b[M + l + 1] = map.stepper().step(t, h, b[M + l], w0, w1, maps ? (*maps)[l] : scratch);
  }
  Eigen::VectorXd out(map.dimension());
  for (long j = 0; j <= M; ++j) out.segment<D>(j * D) = b[K + j];
  return out;
}

// Monodromy::perform_op's fractional branch before delay_tap (the aligned branch is unchanged).
template <int D>
Eigen::VectorXd old_monodromy_apply(const HistoryGrid& grid, const std::vector<StepMap<D>>& maps,
                                    const Eigen::VectorXd& x) {
  using V = Vec<D>;
  const long M = grid.M, m = grid.m, K = grid.K;
  const double theta = grid.theta, c0 = 1 - theta;
  std::vector<double> work(static_cast<size_t>(M + 1 + K) * D);
  std::copy(x.data(), x.data() + x.size(), work.begin());
  auto block = [&](long j) { return Eigen::Map<V>(work.data() + j * D); };
  for (long l = 0; l < K; ++l) {
    const StepMap<D>& s = maps[l];
    const long j = M + l - m;
    V w0 = c0 * block(j) + theta * block(j - 1);
    V w1 = c0 * block(j + 1) + theta * block(j);
    block(M + l + 1).noalias() = s.P * block(M + l) + s.Q * w0 + s.R * w1;
  }
  return Eigen::Map<const Eigen::VectorXd>(work.data() + K * D, x.size());
}

}  // namespace

TEST(DelayTap, EqualsTheOldFormulaOnAlignedAndFractionalGrids) {
  std::mt19937_64 engine(7);
  std::uniform_real_distribution<double> uniform(-1, 1);
  for (const HistoryGrid& grid : {aligned_grid(), fractional_grid()}) {
    using V = Vec<2>;
    std::vector<V> b(static_cast<size_t>(grid.M + 1 + 3 * grid.K));
    for (V& v : b) v = V(uniform(engine), uniform(engine));
    auto slot = [&b](long i) -> const V& { return b[i]; };
    const long M = grid.M, m = grid.m;
    const double theta = grid.theta, c0 = 1 - theta, h = grid.h;
    // three maps' worth of steps: the time wraps at every period
    for (long l = 0; l < 3 * grid.K - 1; ++l) {
      const DelayTap<V> tap = grid.delay_tap<V>(l, slot);
      const long j = M + l - m;
      const V w0 = theta == 0 ? b[j] : V(c0 * b[j] + theta * b[j - 1]);
      const V w1 = theta == 0 ? b[j + 1] : V(c0 * b[j + 1] + theta * b[j]);
      EXPECT_EQ(tap.w0, w0) << "l = " << l << ", theta = " << theta;
      EXPECT_EQ(tap.w1, w1) << "l = " << l << ", theta = " << theta;
      EXPECT_EQ(tap.t, static_cast<double>(l % grid.steps_per_period) * h) << "l = " << l;
      EXPECT_EQ(grid.delayed_slot(l), j);
    }
  }
  EXPECT_EQ(aligned_grid().theta, 0);
  EXPECT_GT(fractional_grid().theta, 0);
}

TEST(DelayTap, StroboscopicMapAndMonodromyReproduceTheOldLoopsBitForBit) {
  // Mackey-Glass (nonlinear, d = 1) and Mathieu (forced, d = 2, the time enters the step).
  for (const HistoryGrid& g : {aligned_grid(), fractional_grid()}) {
    MackeyGlassParameters mg;
    mg.tau = g.tau;
    mg.period = g.period;
    const MackeyGlassModel mackey_glass(mg);
    const StroboscopicMap<MackeyGlassModel> map(TrapezoidStepper<MackeyGlassModel>(mackey_glass), g);
    Eigen::VectorXd U = map.constant_history(mackey_glass.initial_state());
    for (long i = 0; i < U.size(); ++i) U[i] += 0.01 * std::sin(static_cast<double>(i));
    std::vector<StepMap<1>> maps;
    const Eigen::VectorXd expected = old_map_apply(map, U, &maps);
    EXPECT_TRUE(same_bits(map.apply(U), expected)) << "theta = " << g.theta;
    const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(U.size(), -1, 1);
    Eigen::VectorXd y;
    map.monodromy(U).apply(x, y);
    if (g.theta != 0) {
      EXPECT_TRUE(same_to_rounding(y, old_monodromy_apply<1>(g, maps, x))) << "theta = " << g.theta;
    }
  }
  // d = 2: Mathieu (forced, the time enters the step; tau = T, aligned) and the impact
  // oscillator (events) with tau / T = 1 / sqrt(2) (fractional).
  ImpactParameters ip;
  ip.tau_over_T = 1 / std::sqrt(2.0);
  const ImpactModel impact(ip);
  const MathieuModel mathieu;
  const StroboscopicMap<MathieuModel> aligned(TrapezoidStepper<MathieuModel>(mathieu),
                                              make_grid(mathieu.tau(), mathieu.period(), 12));
  const StroboscopicMap<ImpactModel> fractional(TrapezoidStepper<ImpactModel>(impact),
                                                make_grid(impact.tau(), impact.period(), 12));
  ASSERT_EQ(aligned.grid().theta, 0);
  ASSERT_GT(fractional.grid().theta, 0);
  const Eigen::VectorXd Ua = Eigen::VectorXd::LinSpaced(aligned.dimension(), -0.5, 0.7);
  EXPECT_TRUE(same_bits(aligned.apply(Ua), old_map_apply(aligned, Ua)));
  const Eigen::VectorXd Uf = fractional.constant_history(impact.initial_state());
  std::vector<StepMap<2>> maps;
  const Eigen::VectorXd expected = old_map_apply(fractional, Uf, &maps);
  EXPECT_TRUE(same_bits(fractional.apply(Uf), expected));
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(Uf.size(), -1, 1);
  Eigen::VectorXd y;
  fractional.monodromy(Uf).apply(x, y);
  EXPECT_TRUE(same_to_rounding(y, old_monodromy_apply<2>(fractional.grid(), maps, x)));
}
