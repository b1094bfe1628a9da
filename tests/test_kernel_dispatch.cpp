// Every kernel path of the monodromy (kernel_dispatch.hpp) against a reference written here from
// grid.delay_tap (one vector at a time, Eigen fixed-size products: the formula as stated, no
// kernel code) and against to_dense(), for d = 1, 2 (AVX2 path in the library) and d = 3 (a
// dimension instantiated outside the library: portable path only), aligned and fractional
// delays, k = 1, 2, 3, 5, 8, 16, 32, 33 vectors: the compile-time block sizes 2, 4, 8, 16, 32 of
// block_steps and the generic loop (3, 5, 33: not multiples of the vector width). The portable
// path is forced by DELAYSPEC_KERNEL=baseline, as a user would.
//
// apply_block has two layouts (monodromy.hpp): streaming when the delay is at least one map long
// (K <= m: no computed slot is read back), else the whole interleaved history. The grids below
// cover both, each with theta = 0 and theta != 0; the streaming ones run several chunks of steps
// with a short last one for k >= 16 (chunks of max(8, 1024 / (d k)) steps against K = 20-40).
// Streaming for d = 2 runs the fused kernels (no staging): on the AVX2 path for k a multiple of 4
// (4, 8, 12, 16, 32 here; stream_steps_avx2: pairs of steps, a lone last step when K is odd, K = 21
// below), else the portable one for k even (2 on the AVX2 path; 2, 4, .., 32 on the baseline path;
// stream_steps_portable: pairs of vectors, 2 + 4 for k = 6 (not a multiple of 4)); odd k (3, 5,
// 33) and d = 1, 3 stream through the staging buffers. Every check asserts the layout that ran
// (Monodromy::last_block_layout).
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <random>
#include <string>

#include "delayspec/errors.hpp"
#include "delayspec/monodromy.hpp"
#include "test_support.hpp"

using namespace delayspec;
using delayspec::testing::KernelEnv;
using delayspec::testing::random_matrix;

namespace {

bool cpu_has_avx2_fma() { return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"); }

// Step maps shaped like a trapezoid step's, h = 1 / N: P = I + h A, Q = R = h B / 2 with random
// A, B. The product of K of them stays O(1) in norm, so relative errors are meaningful.
template <int D>
std::vector<StepMap<D>> random_maps(long K, int N, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  const double h = 1.0 / N;
  std::vector<StepMap<D>> maps(static_cast<size_t>(K));
  for (StepMap<D>& s : maps)
    for (int r = 0; r < D; ++r)
      for (int c = 0; c < D; ++c) {
        s.P(r, c) = (r == c ? 1 : 0) + h * g(rng);
        s.Q(r, c) = 0.5 * h * g(rng);
        s.R(r, c) = 0.5 * h * g(rng);
      }
  return maps;
}

// y = M x by the definition: b[M+l+1] = P b[M+l] + Q w0 + R w1 with (w0, w1) = grid.delay_tap.
template <int D>
Eigen::VectorXd reference_apply(const HistoryGrid& grid, const std::vector<StepMap<D>>& maps,
                                const Eigen::VectorXd& x) {
  using V = Vec<D>;
  std::vector<V> b(static_cast<size_t>(grid.M + 1 + grid.K));
  for (long j = 0; j <= grid.M; ++j) b[j] = x.segment<D>(j * D);
  auto slot = [&b](long i) -> const V& { return b[i]; };
  for (long l = 0; l < grid.K; ++l) {
    const DelayTap<V> tap = grid.delay_tap<V>(l, slot);
    const StepMap<D>& s = maps[l];
    b[grid.M + l + 1] = s.P * b[grid.M + l] + s.Q * tap.w0 + s.R * tap.w1;
  }
  Eigen::VectorXd y(x.size());
  for (long j = 0; j <= grid.M; ++j) y.segment<D>(j * D) = b[grid.K + j];
  return y;
}

// The tolerance. Every path sums the same 3 D terms per component per step in its own order,
// with or without FMA (one rounding instead of two): each step perturbs its output by a few
// eps relative to the terms, and K steps of maps of norm 1 + O(h) accumulate at most c K eps:
// ~1e-14 of the result's norm for K <= ~100, ~5e-14 for the K = 600 grids (at worst; as a random
// walk ~sqrt(K) eps). 1e-13 leaves a factor 2-10; a wrong coefficient, slot or interpolation
// weight is an O(h) error, >= 1e-3 here.
constexpr double kTol = 1e-13;

// The layout apply_block must take for k vectors (X and Y distinct): the rule of
// Monodromy::apply_block_raw and apply_block_streaming, restated.
template <int D>
typename Monodromy<D>::BlockLayout expected_layout(const Monodromy<D>& op, long k) {
  using Layout = typename Monodromy<D>::BlockLayout;
  const HistoryGrid& g = op.grid();
  if (k == 1) return Layout::single;
  const bool streams = g.delayed_slot(0) - (g.theta == 0 ? 0 : 1) >= 0 && g.delayed_slot(0) + g.K <= g.M;
  if (!streams) return Layout::linear;
  if (D != 2) return Layout::streaming;
  if (op.kernel_path() == KernelPath::avx2 && k % 4 == 0) return Layout::fused_avx2;
  return k % 2 == 0 ? Layout::fused_portable : Layout::streaming;
}

// apply_block on k = 1 .. 33 columns and apply on one vector, against the reference and
// against to_dense() of an operator on the baseline path.
template <int D>
void expect_path_matches(const Monodromy<D>& op, const Eigen::MatrixXd& dense_baseline) {
  const HistoryGrid& grid = op.grid();
  for (long k : {1L, 2L, 3L, 4L, 5L, 6L, 8L, 12L, 16L, 32L, 33L}) {
    SCOPED_TRACE("d = " + std::to_string(D) + ", k = " + std::to_string(k) + ", path " +
                 kernel_path_name(op.kernel_path()) + ", theta = " + std::to_string(grid.theta));
    const Eigen::MatrixXd X = random_matrix(op.rows(), k, 100 + static_cast<unsigned>(k));
    Eigen::MatrixXd Y;
    op.apply_block(X, Y);
    EXPECT_EQ(op.last_block_layout(), expected_layout(op, k));
    Eigen::MatrixXd reference(op.rows(), k);
    for (long v = 0; v < k; ++v) reference.col(v) = reference_apply<D>(grid, op.step_maps(), X.col(v));
    EXPECT_LE((Y - reference).norm(), kTol * reference.norm());
    const Eigen::MatrixXd by_dense = dense_baseline * X;
    EXPECT_LE((Y - by_dense).norm(), kTol * by_dense.norm());
    Eigen::VectorXd y;
    op.apply(X.col(0), y);
    EXPECT_LE((y - reference.col(0)).norm(), kTol * reference.col(0).norm());
  }
  // The operator's own dense matrix (built by its own path, 32 columns at a time) agrees too.
  EXPECT_LE((op.to_dense() - dense_baseline).norm(), kTol * dense_baseline.norm());
}

// The baseline path (forced) and the dispatched path on one grid, d = D.
template <int D>
void check_all_paths(const HistoryGrid& grid) {
  const auto maps = random_maps<D>(grid.K, grid.N, 7 + D);
  std::optional<Monodromy<D>> baseline, dispatched;
  {
    KernelEnv env("baseline");
    baseline.emplace(grid, maps);
  }
  {
    KernelEnv env("");  // unset: the run-time choice
    dispatched.emplace(grid, maps);
  }
  ASSERT_EQ(baseline->kernel_path(), KernelPath::baseline);
  // The dispatched path is AVX2 exactly when the library has one for D and the CPU runs it, so
  // on an AVX2 machine this test does compare two different machine codes.
  const bool avx2 = Monodromy<D>::kHasAvx2Kernel && cpu_has_avx2_fma();
  ASSERT_EQ(dispatched->kernel_path(), avx2 ? KernelPath::avx2 : KernelPath::baseline);

  // The reference itself against the definition on a unit vector: column 0 of the dense matrix.
  const Eigen::MatrixXd dense = baseline->to_dense();
  Eigen::VectorXd e0 = Eigen::VectorXd::Zero(baseline->rows());
  e0(0) = 1;
  ASSERT_LE((reference_apply<D>(grid, maps, e0) - dense.col(0)).norm(), kTol * dense.col(0).norm());

  expect_path_matches(*baseline, dense);
  expect_path_matches(*dispatched, dense);
}

// Streaming layout (K <= m).
HistoryGrid aligned_grid() {
  HistoryGrid g = make_grid(1.0, 1.0, 40);  // tau = T: K = M = m = 40, theta = 0
  EXPECT_TRUE(g.aligned());
  EXPECT_LE(g.K, g.m);
  return g;
}
HistoryGrid aligned_long_delay_grid() {
  HistoryGrid g = make_grid(2.0, 1.0, 40);  // tau = 2 T: K = 20, M = m = 40; Y's slots 0 .. 20 are x's
  EXPECT_TRUE(g.aligned());
  EXPECT_LT(g.K, g.M);
  return g;
}
HistoryGrid aligned_long_delay_odd_grid() {
  HistoryGrid g = make_grid(2.0, 1.0, 42);  // tau = 2 T: K = 21 (odd: the fused kernel's lone last step)
  EXPECT_TRUE(g.aligned());
  EXPECT_EQ(g.K % 2, 1);
  EXPECT_LE(g.K, g.m);
  return g;
}
HistoryGrid fractional_long_delay_grid() {
  HistoryGrid g = make_grid(1.37, 1.0, 29);  // K = 21 <= m = 28, theta in (0, 1)
  EXPECT_FALSE(g.aligned());
  EXPECT_GT(g.theta, 0.0);
  EXPECT_LE(g.K, g.m);
  EXPECT_EQ(g.K % 2, 1);
  EXPECT_EQ(g.delayed_slot(0), 1);  // theta != 0 reads slot j0 - 1 = 0, x's first
  return g;
}
// Longer maps: the fused AVX2 kernel runs the steps in runs of 512 (all vectors per run; each run
// restarts from X and the result slots already in Y), so K = 600 is a full run and a short one,
// K = 601 ends on an odd run.
HistoryGrid aligned_many_runs_grid() {
  HistoryGrid g = make_grid(1.0, 1.0, 600);  // tau = T: K = M = 600
  EXPECT_TRUE(g.aligned());
  EXPECT_GT(g.K, 512);
  return g;
}
HistoryGrid aligned_many_runs_odd_grid() {
  HistoryGrid g = make_grid(1.0, 1.0, 601);  // K = 601
  EXPECT_TRUE(g.aligned());
  EXPECT_EQ(g.K % 2, 1);
  EXPECT_GT(g.K, 512);
  return g;
}
HistoryGrid fractional_many_runs_grid() {
  HistoryGrid g = make_grid(1.37, 1.0, 760);  // K > 512, theta in (0, 1)
  EXPECT_FALSE(g.aligned());
  EXPECT_GT(g.K, 512);
  EXPECT_LE(g.K, g.m);
  return g;
}
// Linear layout (K > m: the steps read slots they computed).
HistoryGrid fractional_grid() {
  HistoryGrid g = make_grid(1.0, 1.37, 29);  // tau / T not a ratio of small integers: theta in (0, 1)
  EXPECT_FALSE(g.aligned());
  EXPECT_GT(g.theta, 0.0);
  EXPECT_GT(g.K, g.m);
  return g;
}
HistoryGrid aligned_short_delay_grid() {
  HistoryGrid g = make_grid(1.0, 2.0, 20);  // tau = T / 2: K = 40 > m = 20, theta = 0
  EXPECT_TRUE(g.aligned());
  EXPECT_GT(g.K, g.m);
  return g;
}

}  // namespace

TEST(KernelDispatch, ScalarAlignedDelay) { check_all_paths<1>(aligned_grid()); }
TEST(KernelDispatch, ScalarFractionalDelay) { check_all_paths<1>(fractional_grid()); }
TEST(KernelDispatch, TwoDimensionalAlignedDelay) { check_all_paths<2>(aligned_grid()); }
TEST(KernelDispatch, TwoDimensionalFractionalDelay) { check_all_paths<2>(fractional_grid()); }
TEST(KernelDispatch, DelayLongerThanTheMapStreams) {
  check_all_paths<1>(aligned_long_delay_grid());
  check_all_paths<1>(fractional_long_delay_grid());
  check_all_paths<2>(aligned_long_delay_grid());
  check_all_paths<2>(aligned_long_delay_odd_grid());
  check_all_paths<2>(fractional_long_delay_grid());
}
// In place (Y is X): the streaming layouts would overwrite x's slots before reading them, so
// apply_block falls back to the linear one, which reads all of x first. Out of place the same
// operator streams (fused on AVX2); both sum the same terms in the same order, so they agree to
// rounding (kTol, as any two paths).
TEST(KernelDispatch, InPlaceApplyBlockMatchesOutOfPlace) {
  const HistoryGrid grid = aligned_long_delay_grid();
  const Monodromy<2> op(grid, random_maps<2>(grid.K, grid.N, 5));
  Eigen::MatrixXd X = random_matrix(op.rows(), 8, 11), Y;
  op.apply_block(X, Y);
  EXPECT_EQ(op.last_block_layout(), expected_layout(op, 8));
  EXPECT_NE(op.last_block_layout(), Monodromy<2>::BlockLayout::linear);  // fused, on either path
  op.apply_block(X, X);
  EXPECT_EQ(op.last_block_layout(), Monodromy<2>::BlockLayout::linear);
  EXPECT_LE((X - Y).norm(), kTol * Y.norm());
}
TEST(KernelDispatch, LongMapsStreamInRuns) {
  check_all_paths<2>(aligned_many_runs_grid());
  check_all_paths<2>(aligned_many_runs_odd_grid());
  check_all_paths<2>(fractional_many_runs_grid());
}
TEST(KernelDispatch, DelayShorterThanTheMapAligned) {
  check_all_paths<1>(aligned_short_delay_grid());
  check_all_paths<2>(aligned_short_delay_grid());
}
// d = 3 is compiled here, outside the library, like an equation model: the portable path.
TEST(KernelDispatch, DimensionOutsideTheLibraryRunsThePortablePath) {
  check_all_paths<3>(aligned_grid());
  check_all_paths<3>(fractional_grid());
  check_all_paths<3>(fractional_long_delay_grid());
}

TEST(KernelDispatch, AutoIsTheDefaultChoice) {
  KernelEnv env("auto");
  const HistoryGrid grid = aligned_grid();
  const Monodromy<2> op(grid, random_maps<2>(grid.K, grid.N, 3));
  EXPECT_EQ(op.kernel_path(), cpu_has_avx2_fma() ? KernelPath::avx2 : KernelPath::baseline);
}

TEST(KernelDispatch, UnknownKernelNameIsBadInputNamingIt) {
  KernelEnv env("avx512");
  const HistoryGrid grid = aligned_grid();
  try {
    Monodromy<2> op(grid, random_maps<2>(grid.K, grid.N, 3));
    FAIL() << "no exception";
  } catch (const BadInput& e) {
    EXPECT_NE(std::string(e.what()).find("DELAYSPEC_KERNEL = 'avx512'"), std::string::npos) << e.what();
  }
}
