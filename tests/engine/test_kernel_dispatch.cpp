// Every kernel path of the monodromy (kernel_dispatch.hpp) against a reference written here from
// grid.delay_tap (one vector at a time, Eigen fixed-size products: the formula as stated, no
// kernel code) and against to_dense(), for d = 1, 2 (wide paths in the library) and d = 3 (a
// dimension instantiated outside the library: portable path only), aligned and fractional
// delays, k = 1 .. 40 vectors: the compile-time block sizes 2, 4, 8, 16, 32 of block_steps and
// the generic loop (3, 5, 33: not multiples of the vector width). Each path is forced by
// DELAYSPEC_KERNEL (baseline, avx2, avx512), as a user would; the ones this CPU cannot run are
// left out (the test says which ran: the path each operator reports is asserted).
//
// apply_block has two layouts (monodromy.hpp): streaming when the delay is at least one map long
// (K <= m: no computed slot is read back), else the whole interleaved history. The grids below
// cover both, each with theta = 0 and theta != 0; the streaming ones run several chunks of steps
// with a short last one for k >= 16 (chunks of max(8, 1024 / (d k)) steps against K = 20-40).
// Streaming for d = 2 runs the fused kernels (no staging): on the AVX-512 path for k a multiple of
// 8 (stream_steps_avx512: blocks of 16 vectors and a last one of 8, i.e. k = 8, 24, 40 end on a
// lone block of 8 and 16, 32 do not), on either wide path for k a multiple of 4 otherwise
// (stream_steps_avx2, 8 vectors side by side and a last block of 4: k = 4, 12, 20; on the AVX2
// path also 8 .. 40), both in pairs of steps with a lone last step when K is odd (K = 21 below),
// else the portable one for k even (2, 6, 10 on the wide paths; every even k on the baseline path;
// pairs of vectors, 2 + 4 for k = 6); odd k (3, 5, 33) and d = 1, 3 stream through the staging
// buffers. Every check asserts the layout that ran (Monodromy::last_block_layout). A last block
// narrower than the kernel's widest must not read columns past X's end: GuardPage* below puts the
// end of X (and of Y) against an inaccessible page, which catches such a read in any build.
#include <gtest/gtest.h>

#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
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
bool cpu_has_avx512() { return cpu_has_avx2_fma() && __builtin_cpu_supports("avx512f"); }

// The paths this CPU runs, narrowest first (each can be forced by name).
std::vector<KernelPath> cpu_paths() {
  std::vector<KernelPath> paths{KernelPath::baseline};
  if (cpu_has_avx2_fma()) paths.push_back(KernelPath::avx2);
  if (cpu_has_avx512()) paths.push_back(KernelPath::avx512);
  return paths;
}

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
  if (op.kernel_path() == KernelPath::avx512 && k % 8 == 0) return Layout::fused_avx512;
  if (op.kernel_path() != KernelPath::baseline && k % 4 == 0) return Layout::fused_avx2;
  return k % 2 == 0 ? Layout::fused_portable : Layout::streaming;
}

// apply_block on k = 1 .. 40 columns and apply on one vector, against the reference and
// against to_dense() of an operator on the baseline path.
template <int D>
void expect_path_matches(const Monodromy<D>& op, const Eigen::MatrixXd& dense_baseline) {
  const HistoryGrid& grid = op.grid();
  for (long k : {1L, 2L, 3L, 4L, 5L, 6L, 8L, 10L, 12L, 16L, 20L, 24L, 32L, 33L, 40L}) {
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

// The path an operator of dimension D takes when `forced` is named (or, for nullopt, by the
// run-time choice): the named or widest CPU path, capped at the widest compiled for D.
template <int D>
KernelPath expected_path(std::optional<KernelPath> forced) {
  const KernelPath widest = D == 2 ? KernelPath::avx512 : D == 1 ? KernelPath::avx2 : KernelPath::baseline;
  return std::min(forced ? *forced : cpu_paths().back(), widest);
}

// Every path this CPU runs (forced by name) and the run-time choice on one grid, d = D.
template <int D>
void check_all_paths(const HistoryGrid& grid) {
  const auto maps = random_maps<D>(grid.K, grid.N, 7 + D);
  std::optional<Monodromy<D>> baseline;
  {
    KernelEnv env("baseline");
    baseline.emplace(grid, maps);
  }
  ASSERT_EQ(baseline->kernel_path(), KernelPath::baseline);

  // The reference itself against the definition on a unit vector: column 0 of the dense matrix.
  const Eigen::MatrixXd dense = baseline->to_dense();
  Eigen::VectorXd e0 = Eigen::VectorXd::Zero(baseline->rows());
  e0(0) = 1;
  ASSERT_LE((reference_apply<D>(grid, maps, e0) - dense.col(0)).norm(), kTol * dense.col(0).norm());

  expect_path_matches(*baseline, dense);
  // On an AVX-512 machine, for D = 2 these are three different machine codes of the streaming
  // kernel (portable, AVX2, AVX-512); for D = 1 avx512 is capped at avx2 (asserted).
  for (KernelPath path : cpu_paths()) {
    if (path == KernelPath::baseline) continue;
    KernelEnv env(kernel_path_name(path));
    const Monodromy<D> forced(grid, maps);
    ASSERT_EQ(forced.kernel_path(), expected_path<D>(path)) << kernel_path_name(path);
    expect_path_matches(forced, dense);
  }
  KernelEnv env("");  // unset: the run-time choice, the widest path
  const Monodromy<D> dispatched(grid, maps);
  ASSERT_EQ(dispatched.kernel_path(), expected_path<D>(std::nullopt));
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
  EXPECT_EQ(op.kernel_path(), cpu_paths().back());
  const Monodromy<1> scalar(grid, random_maps<1>(grid.K, grid.N, 3));
  EXPECT_EQ(scalar.kernel_path(), cpu_has_avx2_fma() ? KernelPath::avx2 : KernelPath::baseline);
}

TEST(KernelDispatch, UnknownKernelNameIsBadInputNamingIt) {
  KernelEnv env("avx1024");
  const HistoryGrid grid = aligned_grid();
  try {
    Monodromy<2> op(grid, random_maps<2>(grid.K, grid.N, 3));
    FAIL() << "no exception";
  } catch (const BadInput& e) {
    EXPECT_NE(std::string(e.what()).find("DELAYSPEC_KERNEL = 'avx1024'"), std::string::npos) << e.what();
  }
}

// The fused kernels called directly (kernel_dispatch.hpp) on X and Y whose last column ends where
// an inaccessible page begins: a read of a column past X's k (the AVX2 kernel's unused second
// block did that before 5410999, when k - v = 4) or a write past Y's would fault; and on X and Y
// that start right after one (a read before slot 0, e.g. of the interpolation's slot j0 - 1
// when j0 = 0). k covers a last
// block narrower than the kernel's widest (AVX2: 4, 12, 20; AVX-512: 8, 24, 40) and full ones
// (16, 32), on a grid with runs of steps (K = 600 > 512) and an odd fractional one (K = 21).
// The results must equal apply_block's on ordinary matrices on the same path: the same kernel,
// the same sums, so bit for bit (EXPECT_EQ on the matrices, not a tolerance).
namespace {
enum class GuardAt { end, start };
class GuardedColumns {
 public:
  // n x k doubles whose last element is the last before an inaccessible page (GuardAt::end) or
  // whose first is the first after one (GuardAt::start).
  GuardedColumns(long n, long k, GuardAt at) {
    const long page = sysconf(_SC_PAGESIZE), bytes = 8 * n * k;
    size_ = (bytes + page - 1) / page * page + page;
    base_ = static_cast<char*>(mmap(nullptr, size_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
    if (base_ == MAP_FAILED) throw std::runtime_error("mmap failed");
    char* guard = at == GuardAt::end ? base_ + size_ - page : base_;
    if (mprotect(guard, page, PROT_NONE) != 0) throw std::runtime_error("mprotect failed");
    data_ = reinterpret_cast<double*>(at == GuardAt::end ? guard - bytes : guard + page);
  }
  ~GuardedColumns() { munmap(base_, size_); }
  GuardedColumns(const GuardedColumns&) = delete;
  GuardedColumns& operator=(const GuardedColumns&) = delete;
  double* data() { return data_; }

 private:
  char* base_ = nullptr;
  size_t size_ = 0;
  double* data_ = nullptr;
};

using StreamKernel = void (*)(const StepMap<2>*, long, long, long, double, const double*, long, long, double*, long);

void expect_guarded_kernel_matches(KernelPath path, StreamKernel kernel, const HistoryGrid& grid,
                                   std::initializer_list<long> ks) {
  const auto maps = random_maps<2>(grid.K, grid.N, 13);
  KernelEnv env(kernel_path_name(path));
  const Monodromy<2> op(grid, maps);
  ASSERT_EQ(op.kernel_path(), path);
  const long n = op.rows(), K = grid.K;
  for (long k : ks) {
    SCOPED_TRACE(std::string(kernel_path_name(path)) + ", k = " + std::to_string(k) + ", K = " + std::to_string(K));
    const Eigen::MatrixXd X = random_matrix(n, k, 200 + static_cast<unsigned>(k));
    Eigen::MatrixXd expected;
    op.apply_block(X, expected);
    ASSERT_EQ(op.last_block_layout(), expected_layout(op, k));
    for (GuardAt at : {GuardAt::end, GuardAt::start}) {
      GuardedColumns x(n, k, at), y(n, k, at);
      std::copy(X.data(), X.data() + n * k, x.data());
      std::fill(y.data(), y.data() + n * k, 0.0);
      kernel(maps.data(), K, grid.M, grid.delayed_slot(0), grid.theta, x.data(), n, k, y.data(), n);
      // The kernel writes the result slots M + 1 .. M + K (Y's slots M + 1 - K .. M); apply_block
      // copies x's slots K .. M into Y's first M + 1 - K slots itself.
      const Eigen::Map<const Eigen::MatrixXd> Y(y.data(), n, k);
      const long first = 2 * (grid.M + 1 - K);
      EXPECT_EQ(Y.bottomRows(n - first), expected.bottomRows(n - first));
    }
  }
}
}  // namespace

// Every fused kernel this CPU runs (the portable one always).
TEST(KernelDispatch, GuardPageAfterTheLastColumn) {
  for (const HistoryGrid& grid : {aligned_many_runs_grid(), fractional_long_delay_grid()})
    for (KernelPath path : cpu_paths()) {
      if (path == KernelPath::baseline)  // pairs of vectors: k = 2, 6, 10 end on a lone pair
        expect_guarded_kernel_matches(path, detail::stream_steps_portable, grid, {2, 6, 10});
      if (path == KernelPath::avx2)  // 8 vectors side by side, then 4
        expect_guarded_kernel_matches(path, detail::stream_steps_avx2, grid, {4, 12, 20, 16, 32});
      if (path == KernelPath::avx512)  // 16 vectors side by side, then 8
        expect_guarded_kernel_matches(path, detail::stream_steps_avx512, grid, {8, 24, 40, 16, 32});
    }
}

// Several delays (block_kernel.hpp's multi_delay_steps; AVX2 + FMA code for the shapes of
// kMultiDelayAvx2): every path against the definition (grid.delay_taps, one vector at a time)
// and the baseline's dense matrix, k = 1 .. 33, on grids with every delay fractional, one delay
// aligned, and a delay shorter than the map (computed slots read back). A shape without AVX2
// code (D = 3 with 2 delays, D = 1 with 5) reports and runs the baseline path on every request.
namespace {

template <int D, int DW>
std::vector<StepMap<D, DW>> random_multi_maps(long K, int N, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  const double h = 1.0 / N;
  std::vector<StepMap<D, DW>> maps(static_cast<size_t>(K));
  for (StepMap<D, DW>& s : maps) {
    for (int r = 0; r < D; ++r)
      for (int c = 0; c < D; ++c) s.P(r, c) = (r == c ? 1 : 0) + h * g(rng);
    for (int r = 0; r < D; ++r)
      for (int c = 0; c < DW; ++c) s.Q(r, c) = 0.5 * h * g(rng), s.R(r, c) = 0.5 * h * g(rng);
  }
  return maps;
}

// y = M x by the definition: b[M+l+1] = P b[M+l] + Q w0 + R w1, (w0, w1) = grid.delay_taps.
template <int D, int DW>
Eigen::VectorXd reference_multi_apply(const HistoryGrid& grid, const std::vector<StepMap<D, DW>>& maps,
                                      const Eigen::VectorXd& x) {
  std::vector<Vec<D>> b(static_cast<size_t>(grid.M + 1 + grid.K));
  for (long j = 0; j <= grid.M; ++j) b[j] = x.segment<D>(j * D);
  auto slot = [&b](long i) -> const Vec<D>& { return b[i]; };
  for (long l = 0; l < grid.K; ++l) {
    const DelayTap<Vec<DW>> tap = grid.delay_taps<D, Vec<DW>>(l, slot);
    const StepMap<D, DW>& s = maps[l];
    b[grid.M + l + 1] = s.P * b[grid.M + l] + s.Q * tap.w0 + s.R * tap.w1;
  }
  Eigen::VectorXd y(x.size());
  for (long j = 0; j <= grid.M; ++j) y.segment<D>(j * D) = b[grid.K + j];
  return y;
}

template <int D, int DW>
void check_multi_delay_paths(const HistoryGrid& grid) {
  const auto maps = random_multi_maps<D, DW>(grid.K, grid.N, 11 + DW);
  std::optional<Monodromy<D, DW>> baseline;
  {
    KernelEnv env("baseline");
    baseline.emplace(grid, maps);
  }
  ASSERT_EQ(baseline->kernel_path(), KernelPath::baseline);
  const Eigen::MatrixXd dense = baseline->to_dense();
  const KernelPath widest = detail::kMultiDelayAvx2<D, DW> ? KernelPath::avx2 : KernelPath::baseline;
  for (KernelPath path : cpu_paths()) {
    KernelEnv env(kernel_path_name(path));
    const Monodromy<D, DW> op(grid, maps);
    ASSERT_EQ(op.kernel_path(), std::min(path, widest)) << kernel_path_name(path);
    for (long k : {1L, 2L, 3L, 4L, 5L, 8L, 16L, 33L}) {
      SCOPED_TRACE("D = " + std::to_string(D) + ", DW = " + std::to_string(DW) + ", k = " + std::to_string(k) +
                   ", path " + kernel_path_name(op.kernel_path()));
      const Eigen::MatrixXd X = random_matrix(op.rows(), k, 200 + static_cast<unsigned>(k));
      Eigen::MatrixXd Y;
      op.apply_block(X, Y);
      using Layout = typename Monodromy<D, DW>::BlockLayout;
      EXPECT_EQ(op.last_block_layout(), k == 1 ? Layout::single : Layout::linear);
      Eigen::MatrixXd reference(op.rows(), k);
      for (long v = 0; v < k; ++v) reference.col(v) = reference_multi_apply<D, DW>(grid, maps, X.col(v));
      EXPECT_LE((Y - reference).norm(), kTol * reference.norm());
      const Eigen::MatrixXd by_dense = dense * X;
      EXPECT_LE((Y - by_dense).norm(), kTol * by_dense.norm());
    }
    EXPECT_LE((op.to_dense() - dense).norm(), kTol * dense.norm());
  }
}

// Grids with n delays, at least one fractional (theta != 0: slot j - 1 is read) and one shorter
// than the map (K > m_i: the steps read back slots they computed).
HistoryGrid several_delay_grid(const std::vector<double>& taus, int N) {
  HistoryGrid g = make_grid(taus, 1.0, N);
  EXPECT_EQ(g.delays.size(), taus.size());
  bool fractional = false, short_delay = false;
  for (const auto& p : g.delays) fractional = fractional || p.theta > 0, short_delay = short_delay || g.K > p.m;
  EXPECT_TRUE(fractional);
  EXPECT_TRUE(short_delay);
  return g;
}
// The ratios irrational (sqrt 2, sqrt 0.5, sqrt 0.3); N a multiple of 13 and 11 where the longest
// delay is 1.3 or 1.1 periods (a period is a whole number of steps).
HistoryGrid two_delay_grid() { return several_delay_grid({0.7, 0.7 * std::sqrt(2.0)}, 40); }
HistoryGrid three_delay_grid() { return several_delay_grid({1.3, 0.45, std::sqrt(0.5)}, 39); }
HistoryGrid four_delay_grid() { return several_delay_grid({0.25, 1.1, std::sqrt(0.3), 0.9}, 44); }
HistoryGrid five_delay_grid() { return several_delay_grid({0.25, 1.1, std::sqrt(0.3), 0.9, 0.6}, 44); }

}  // namespace

TEST(KernelDispatch, SeveralDelaysEveryPathAgreesWithTheDefinition) {
  check_multi_delay_paths<1, 2>(two_delay_grid());
  check_multi_delay_paths<2, 4>(two_delay_grid());
  check_multi_delay_paths<1, 3>(three_delay_grid());
  check_multi_delay_paths<2, 6>(three_delay_grid());
  check_multi_delay_paths<1, 4>(four_delay_grid());
  check_multi_delay_paths<2, 8>(four_delay_grid());
}
TEST(KernelDispatch, SeveralDelaysOfAShapeWithoutWideCodeRunThePortablePath) {
  check_multi_delay_paths<3, 6>(two_delay_grid());
  check_multi_delay_paths<1, 5>(five_delay_grid());
}
