#pragma once
// Lyapunov exponents of the discretised stroboscopic map (design.md 1.7).
//
// A block of k tangent vectors (k = `exponents`, much smaller than n = d (M + 1)) is carried
// along the trajectory, fused with it step by step: each step of the stepper produces its
// linearisation, which is applied at once to the k interleaved tangent vectors
// (block_kernel.hpp, apply_step_linearisation) and then forgotten; no step map is stored, and
// for a step that is one trapezoid sub-step (no event or time switch in it) none is formed:
// its factored derivative S^{-1} [L du_0 + Bl dw0 + Br dw1] is applied directly
// (detail/sub_step_derivative.hpp). Every `qr_every` stroboscopic
// periods the n x k block is Householder-QR factorised in place (TangentQR), log |R_ii| is
// accumulated and the block is replaced by Q. The first `transient` periods (trajectory and
// tangent block both advance, so the block has time to align with the leading Lyapunov
// vectors) are discarded. Exponents come per stroboscopic period ("per period": one map, p
// forcing periods when periods_per_map = p) and per unit time (divided by K h = p T), with an
// error that covers random and bounded deterministic fluctuations (below).
//
// Error of an exponent. Let x_1..x_I be the interval sums of log R_jj (I intervals of q =
// qr_every periods, n = I q periods), S(i) = x_1 + .. + x_i, and the reported exponent
// lambda = S(I) / n. Write S(i) = i q lambda_true + g(i): lambda - lambda_true = (g(I) - g(0)) / n.
//   * Random fluctuations (chaos): g is a random walk, sd(g(I)) = sigma sqrt(n). Batch means
//     estimate it: SE = sd(B batch means) / sqrt(B) ~ sigma / sqrt(n).
//   * Bounded deterministic fluctuations: on a periodic orbit whose leading multipliers are a
//     complex pair mu, conj(mu), prod R_11 = |M^n q0| = |mu|^n |S Rot(n arg mu) S^+ q0| with
//     S = [Re v, Im v]: g oscillates with the rotation phase inside [-log cond S, log cond S]
//     and never averages out; likewise the alignment of the block after a short transient adds
//     a bounded excess. The error is then up to range(g) / n, and batch means miss it when the
//     rotation per batch is near a multiple of 2 pi (every batch sees the same phase change):
//     measured 60 SE on the impact orbit of tests/engine/test_lyapunov.cpp.
//   The detrended cumulative sum D(i) = S(i) - (i / I) S(I) = g(i) - g(0) - (i / I)(g(I) - g(0))
//   is observable (D(0) = D(I) = 0). For a bounded g that goes through its range in P intervals,
//   range_i D >= range g - (P / I) |g(I) - g(0)| >= |g(I) - g(0)| (1 - P / I), so
//       fluctuation bound F = (max_i D(i) - min_i D(i)) / n
//   bounds |lambda - lambda_true| up to the fraction P / I (small when the run covers many
//   rotations or the excess dies out early). For a random walk D is a Brownian bridge whose
//   range has mean sqrt(pi / 2) sigma sqrt(n) (Kuiper), so F ~ 1.25 SE. Reported error
//   (LyapunovResult::error_per_period; the JSON key keeps its historical name
//   standard_error_per_period):
//       error = sqrt(SE^2 + F^2).
//   On a bounded fluctuation it is >= F, and where F falls short by the fraction P / I (an
//   excess concentrated in the first P intervals, i.e. in the first batch) SE = |bias| exactly
//   (one batch mean off by B |bias|, the others not: SE = |bias|), so the sum covers
//   the bias with a margin of up to sqrt(2). On noise both parts estimate sigma / sqrt(n): the
//   error is ~1.6 sigma / sqrt(n) (measured 1.6 on white noise), not a 1-sigma band but within
//   a small factor of it. On chaotic runs the error measured 1.3x the batch SE (Mackey-Glass);
//   for bounded fluctuations with a random end phase (the zero exponent of the flow direction)
//   both SE and F overestimate the actual spread (SE by about sqrt(B), since it assumes
//   random-walk scaling), so the error is a conservative bound there (tests/engine/test_lyapunov.cpp).
//   Both parts are also reported (batch_standard_error_per_period, fluctuation_bound_per_period).
//
// Subnormals: each period's steps run with subnormal numbers flushed to zero
// (detail/flush_subnormals.hpp): a trajectory decaying to a zero orbit otherwise reaches the
// subnormal range and every later step is about twice as slow; what is flushed is below
// 1e-300 of the O(1) quantities it would be added to.
//
// Layout (as StroboscopicMap and Monodromy): linear buffers of M + 1 + K slots for the
// trajectory and for the block; slots 0..M hold the history at the start of a period, step l
// writes slot M + l + 1, the history at the end is slots K..K+M. There the block is factorised
// in place with Q written straight to slots 0..M (TangentQR allows the overlap), and the
// trajectory slots are moved down. All buffers are allocated once per call.
//
// QR interval. With qr_every = q > 1 the block is not re-orthonormalised for q periods, so its
// columns separate by the ratio of the Floquet/Lyapunov growth factors over q periods; the
// k-th column then keeps only about 16 - log10(R_11 / R_kk) digits, and a large enough growth
// overflows. The run therefore checks every QR of an interval q > 1: if max_i |log R_ii| > 300
// (entries near 1e130, halfway to overflow) or R_11 / R_kk > 1e8 (fewer than 8 digits left in
// the k-th direction) it stops with NumericalFailure asking for a smaller qr_every. With
// qr_every = 1 (the default) no such check applies: any loss is then a property of one period
// of the map itself.
//
// Errors: BadInput for invalid options (named by their CLI keys: exponents, periods,
// transient, qr_every, batches); NumericalFailure when the trajectory or the block stops being
// finite or a tangent vector becomes numerically dependent on the others (TangentQR).
//
// Example:
//   StroboscopicMap<LinearModel> map(TrapezoidStepper<LinearModel>(model), grid);
//   LyapunovResult r = lyapunov_exponents(map, map.constant_history(Vec<1>(1)), LyapunovOptions{});
//   r.per_time[0] +- r.error_per_time[0]   // the error of the header comment
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "delayspec/cancellation.hpp"
#include "delayspec/detail/block_kernel.hpp"
#include "delayspec/detail/flush_subnormals.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/stroboscopic_map.hpp"
#include "delayspec/detail/tangent_qr.hpp"

namespace delayspec {

// The most tangent vectors a run carries: the QR kernel keeps one row of the block in stack
// buffers of this size (tangent_qr.cpp); only leading exponents are meant.
inline constexpr int kMaxTangentVectors = 64;

struct LyapunovOptions {
  int exponents = 2;        // k: tangent vectors (exponents wanted), 1 <= k <= min(n, kMaxTangentVectors)
  long periods = 1000;      // stroboscopic periods averaged (a multiple of qr_every)
  long transient = 100;     // periods discarded first (>= 0)
  std::uint64_t seed = 1;   // initial tangent block: a fixed pseudo-random n x k block, orthonormalised
  int qr_every = 1;         // periods between QR factorisations (see the header comment)
  int batches = 20;         // batch means: measured QR intervals are split into this many batches
  long section_points = 0;  // record u_0 at this many forcing-period boundaries after the transient
  // Called after every period with (periods done, periods in total incl. the transient); may be empty.
  std::function<void(long, long)> progress;
};

struct LyapunovResult {
  std::vector<double> per_period;        // sum log |R_ii| / periods, largest first as computed
  std::vector<double> per_time;          // per_period / (K h)
  std::vector<double> error_per_period;  // the error: sqrt(batch SE^2 + fluctuation bound^2) (header comment)
  std::vector<double> error_per_time;    // error_per_period / (K h)
  std::vector<double> batch_standard_error_per_period;  // batch means: sd(batch means) / sqrt(batches)
  std::vector<double> fluctuation_bound_per_period;     // range of the detrended cumulative sum / periods
  long periods = 0, transient = 0;
  int qr_every = 1, batches = 0;
  double map_time = 0;            // K h: the time of one stroboscopic period
  long steps = 0;                 // stepper steps taken (transient included)
  double seconds = 0;             // wall time of the whole run
  double qr_seconds = 0;          // of which: QR factorisations and forming Q
  Eigen::VectorXd final_history;  // the trajectory's history at the end
  Eigen::MatrixXd section;        // section_points x d: y(t0 + j T), one row per forcing period
};

// Fills the n x k row-major block with a reproducible pseudo-random matrix (entries uniform
// in [-1/2, 1/2) from a 64-bit mt19937 stream, the same on every platform).
void random_block(double* block, long n, int k, std::uint64_t seed);

// Mean per period and its error (header comment) from the per-interval sums of log |R_ii|
// (interval_logs[i * k + j], intervals of `qr_every` periods each; at least two intervals).
struct LyapunovStatistics {
  std::vector<double> mean_per_period;       // S(I) / n
  std::vector<double> batch_standard_error;  // sd(batch means) / sqrt(batches)
  std::vector<double> fluctuation_bound;     // (max_i D(i) - min_i D(i)) / n
  std::vector<double> error;                 // sqrt(batch_standard_error^2 + fluctuation_bound^2)
  int batches = 0;                           // batches used: min(batches, intervals)
};
LyapunovStatistics lyapunov_statistics(const std::vector<double>& interval_logs, int k, int qr_every, int batches);

// Validates options against the dimension n (BadInput naming the CLI key).
void validate_lyapunov_options(const LyapunovOptions& options, long n);

// The k leading Lyapunov exponents of the stroboscopic map starting from history U0.
template <class Model, class Stepper>
LyapunovResult lyapunov_exponents(const StroboscopicMap<Model, Stepper>& map, const Eigen::VectorXd& U0,
                                  const LyapunovOptions& options) {
  constexpr int D = Model::d;
  constexpr int DW = delayed_rows<Model>;  // D, or D n with n delays (model.hpp)
  using V = Vec<D>;
  using W = DelayedVec<Model>;
  const HistoryGrid& grid = map.grid();
  const long n = map.dimension();
  validate_lyapunov_options(options, n);
  if (U0.size() != n)
    throw BadInput("lyapunov_exponents: initial history has " + std::to_string(U0.size()) + " entries, expected " +
                   std::to_string(n));
  if (!U0.allFinite()) throw BadInput("lyapunov_exponents: the initial history is not finite");

  const auto start = std::chrono::steady_clock::now();
  const long M = grid.M, K = grid.K, spp = grid.steps_per_period;
  const int k = options.exponents;
  const long stride = static_cast<long>(D) * k;  // one slot of the block
  const Stepper& stepper = map.stepper();

  std::vector<V> traj(static_cast<size_t>(M + 1 + K));
  for (long j = 0; j <= M; ++j) traj[j] = U0.template segment<D>(j * D);
  std::vector<double> block(static_cast<size_t>((M + 1 + K) * stride));
  double* const result_slots = block.data() + K * stride;  // slots K..K+M: the block after a period
  double* const q_out = block.data();                      // Q -> slots 0..M (may overlap slots K..K+M: TangentQR)
  TangentQR qr(result_slots, n, k);
  std::vector<double> log_r(k);
  double qr_seconds = 0;

  // QR of the block in slots K..K+M; Q into slots 0..M; log |R_ii| into log_r.
  auto reorthonormalise = [&] {
    const auto t0 = std::chrono::steady_clock::now();
    qr.factorise(q_out, log_r.data());
    qr_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  random_block(result_slots, n, k, options.seed);
  reorthonormalise();

  LyapunovResult result;
  result.section.resize(options.section_points, D);
  long section_count = 0;
  // One stroboscopic period, trajectory and block fused; afterwards the trajectory history is
  // back in slots 0..M and the (unnormalised) block in slots K..K+M.
  // KC: k as a compile-time constant for the common few vectors (step_block), else 0.
  auto advance_with = [&]<int KC>(bool record) {
    // A decaying trajectory would go subnormal and run ~2x slower (flush_subnormals.hpp)
    const detail::FlushSubnormals flush_subnormals;
    // Local copies: the grid's doubles (h, theta) and the buffers' pointers stay in registers
    // (through the captured references they were reloaded every step: a store of a double may
    // alias them)
    const HistoryGrid g = grid;
    [[maybe_unused]] const DelayPlaces<DW / D> places(g.delays);  // several delays only
    V* const u = traj.data();
    double* const b = block.data();
    auto slot = [u](long i) -> const V& { return u[i]; };
    for (long l = 0; l < K; ++l) {
      const DelayTap<W> tap = g.template delay_taps<D, W>(l, slot);
      StepLinearisation<D, DW> step_linearisation;  // a local: kept in registers where the step inlines
      u[M + l + 1] = stepper.step(tap.t, tap.h, u[M + l], tap.w0, tap.w1, step_linearisation);
      // du_0(t+h) = P du_0 + Q dy_tau(t) + R dy_tau(t+h) for the k tangent vectors (the same
      // tap), P, Q, R not formed where the step is one sub-step (apply_step_linearisation)
      if constexpr (DW != D)
        multi_delay_step<D, DW, KC>(step_linearisation, b, M + l, places, k, b + (M + l + 1) * stride);
      else
        apply_step_linearisation<D, KC>(step_linearisation, b + (M + l) * stride, b + g.delayed_slot(l) * stride, k,
                                        g.theta, b + (M + l + 1) * stride);
      if (record && section_count < options.section_points && (l + 1) % spp == 0)  // (no division unless recording)
        result.section.row(section_count++) = u[M + l + 1].transpose();
    }
    std::copy(traj.begin() + K, traj.end(), traj.begin());  // history at the end -> slots 0..M
  };
  auto advance = [&](bool record) {
    switch (k) {
      case 1: return advance_with.template operator()<1>(record);
      case 2: return advance_with.template operator()<2>(record);
      default: return advance_with.template operator()<0>(record);
    }
  };
  auto check_interval = [&](int interval) {
    if (interval <= 1) return;
    const auto [lo, hi] = std::minmax_element(log_r.begin(), log_r.end());
    const double biggest = std::max(std::abs(*lo), std::abs(*hi));
    if (biggest > 300 || *hi - *lo > 18.420680743952367)  // e^300 ~ 1e130; log(1e8)
      throw NumericalFailure("`qr_every = " + std::to_string(interval) +
                             "`: within one QR interval the tangent block grew or separated too much (log|R_ii| in [" +
                             format_number(*lo) + ", " + format_number(*hi) +
                             "]; limits 300 and a spread of log(1e8)); use a smaller qr_every");
  };

  const long total = options.transient + options.periods;
  long done = 0;
  // Transient: QR every qr_every periods and at its end; logs discarded.
  for (long p = 0; p < options.transient; ++p) {
    advance(false);
    const bool due = (p + 1) % options.qr_every == 0 || p + 1 == options.transient;
    if (due) {
      reorthonormalise();
      check_interval(options.qr_every);
    } else {
      std::copy(result_slots, result_slots + n * k, block.data());
    }
    if (options.progress) options.progress(++done, total);
    throw_if_cancelled();  // between periods (cancellation.hpp)
  }
  // Measurement.
  const long intervals = options.periods / options.qr_every;
  std::vector<double> interval_logs(static_cast<size_t>(intervals * k));
  for (long i = 0; i < intervals; ++i) {
    for (int q = 0; q < options.qr_every; ++q) {
      advance(true);
      if (q + 1 < options.qr_every) std::copy(result_slots, result_slots + n * k, block.data());
      if (options.progress) options.progress(++done, total);
      throw_if_cancelled();  // between periods (cancellation.hpp)
    }
    reorthonormalise();
    check_interval(options.qr_every);
    std::copy(log_r.begin(), log_r.end(), interval_logs.begin() + i * k);
  }

  LyapunovStatistics stats = lyapunov_statistics(interval_logs, k, options.qr_every, options.batches);
  result.per_period = std::move(stats.mean_per_period);
  result.error_per_period = std::move(stats.error);
  result.batch_standard_error_per_period = std::move(stats.batch_standard_error);
  result.fluctuation_bound_per_period = std::move(stats.fluctuation_bound);
  result.batches = stats.batches;
  result.map_time = static_cast<double>(K) * grid.h;
  for (int i = 0; i < k; ++i) {
    result.per_time.push_back(result.per_period[i] / result.map_time);
    result.error_per_time.push_back(result.error_per_period[i] / result.map_time);
  }
  result.periods = options.periods;
  result.transient = options.transient;
  result.qr_every = options.qr_every;
  result.steps = total * K;
  result.final_history.resize(n);
  for (long j = 0; j <= M; ++j) result.final_history.template segment<D>(j * D) = traj[j];
  result.section.conservativeResize(section_count, D);
  result.qr_seconds = qr_seconds;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace delayspec
