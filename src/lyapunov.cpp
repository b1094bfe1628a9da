#include "delayspec/lyapunov.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

namespace delayspec {

namespace {

// Householder QR of the n x k row-major block a (a[i k + j] = entry i of vector j), in place,
// LAPACK/Eigen conventions: H_j = I - tau_j v v^T with v_j = 1 and the essential part of v stored
// below the diagonal of column j; r[j] = R_jj. Written for the interleaved layout: every pass
// walks the contiguous block row by row and works on all k columns of a row at once (k is a
// compile-time constant KC for k <= 8, so a row is a short vector), with two rows in flight to
// hide the latency of the reductions. Eigen's HouseholderQR on a row-major Ref measured several
// times slower for n = 2002, k = 2 (bench_lyapunov). Cost: about 4 n k^2 flops, 2k + 2 passes
// over the block, and as many to form Q.
//
// Both passes below use this reflector kernel on a row-major n x kc block x (columns c0..kc-1
// of interest): x_c -= tau v (v^T x_c), v_j = 1, v_i = a[i k + j] (i > j).
// A column whose part orthogonal to the previous ones is below n eps of its norm is lost in
// rounding (Householder is backward stable to about n eps |column|): R_jj carries no digits.
double dependence_threshold(long n) { return static_cast<double>(n) * 2.220446049250313e-16; }

template <int KC>
void apply_reflector(const double* a, long n, int k_runtime, int j, double tau, double* x, int c0) {
  const int k = KC > 0 ? KC : k_runtime;
  double w0[KC > 0 ? KC : kMaxTangentVectors], w1[KC > 0 ? KC : kMaxTangentVectors];
  for (int c = c0; c < k; ++c) {
    w0[c] = x[j * k + c];
    w1[c] = 0;
  }
  long i = j + 1;
  for (; i + 1 < n; i += 2) {  // w = v^T x, two rows at a time
    const double v0 = a[i * k + j], v1 = a[(i + 1) * k + j];
    for (int c = c0; c < k; ++c) {
      w0[c] += v0 * x[i * k + c];
      w1[c] += v1 * x[(i + 1) * k + c];
    }
  }
  if (i < n)
    for (int c = c0; c < k; ++c) w0[c] += a[i * k + j] * x[i * k + c];
  for (int c = c0; c < k; ++c) {
    w0[c] = tau * (w0[c] + w1[c]);
    x[j * k + c] -= w0[c];
  }
  for (long r = j + 1; r < n; ++r) {  // x -= v w^T
    const double vr = a[r * k + j];
    for (int c = c0; c < k; ++c) x[r * k + c] -= vr * w0[c];
  }
}

template <int KC>
void householder_rows(double* a, long n, int k_runtime, double* tau, double* r, double* column_norm) {
  const int k = KC > 0 ? KC : k_runtime;
  for (int j = 0; j < k; ++j) {
    const double alpha = a[j * k + j];
    double above = 0;  // R_0j^2 + ... + R_{j-1,j}^2: the reflections so far kept |column j|
    for (int i = 0; i < j; ++i) above += a[i * k + j] * a[i * k + j];
    double t0 = 0, t1 = 0;  // |x_{j+1..n}|^2, two partial sums
    long i = j + 1;
    for (; i + 1 < n; i += 2) {
      t0 += a[i * k + j] * a[i * k + j];
      t1 += a[(i + 1) * k + j] * a[(i + 1) * k + j];
    }
    if (i < n) t0 += a[i * k + j] * a[i * k + j];
    const double tail = t0 + t1;
    column_norm[j] = std::sqrt(above + alpha * alpha + tail);
    if (tail == 0) {  // nothing below the diagonal: H_j = I
      tau[j] = 0;
      r[j] = alpha;
    } else {
      const double beta = -std::copysign(std::sqrt(alpha * alpha + tail), alpha);
      const double inv_v0 = 1 / (alpha - beta);
      for (long q = j + 1; q < n; ++q) a[q * k + j] *= inv_v0;  // v = x / (alpha - beta), v_j = 1
      tau[j] = (beta - alpha) / beta;
      r[j] = beta;
    }
    a[j * k + j] = r[j];
    if (tau[j] != 0 && j + 1 < k) apply_reflector<KC>(a, n, k, j, tau[j], a, j + 1);  // columns c > j
  }
}

// q = H_0 H_1 ... H_{k-1} [I_k; 0] (n x k row-major), from the reflectors stored in a.
template <int KC>
void form_q_rows(const double* a, long n, int k_runtime, const double* tau, double* q) {
  const int k = KC > 0 ? KC : k_runtime;
  std::fill(q, q + n * k, 0.0);
  for (int c = 0; c < k; ++c) q[c * k + c] = 1;
  for (int j = k - 1; j >= 0; --j)
    if (tau[j] != 0) apply_reflector<KC>(a, n, k, j, tau[j], q, j);  // columns c < j vanish in rows >= j
}

template <int KC>
void qr_rows(double* a, long n, int k, double* tau, double* r, double* column_norm, double* q) {
  householder_rows<KC>(a, n, k, tau, r, column_norm);
  for (int i = 0; i < k; ++i)
    if (!(std::abs(r[i]) > dependence_threshold(n) * column_norm[i])) return;  // reported by the caller
  form_q_rows<KC>(a, n, k, tau, q);
}

// Compile-time k for the common small blocks, runtime k (<= kMaxTangentVectors per reflector pass) otherwise.
void qr_rows_dispatch(double* a, long n, int k, double* tau, double* r, double* norm, double* q) {
  switch (k) {
    case 1: return qr_rows<1>(a, n, k, tau, r, norm, q);
    case 2: return qr_rows<2>(a, n, k, tau, r, norm, q);
    case 3: return qr_rows<3>(a, n, k, tau, r, norm, q);
    case 4: return qr_rows<4>(a, n, k, tau, r, norm, q);
    case 5: return qr_rows<5>(a, n, k, tau, r, norm, q);
    case 6: return qr_rows<6>(a, n, k, tau, r, norm, q);
    case 7: return qr_rows<7>(a, n, k, tau, r, norm, q);
    case 8: return qr_rows<8>(a, n, k, tau, r, norm, q);
    default: return qr_rows<0>(a, n, k, tau, r, norm, q);
  }
}

}  // namespace

TangentQR::TangentQR(double* block, long n, int k) : block_(block), n_(n), k_(k), tau_(k), r_(k), norm_(k) {
  if (k > kMaxTangentVectors)
    throw BadInput("`exponents = " + std::to_string(k) + "`: at most " + std::to_string(kMaxTangentVectors) +
                   " tangent vectors");
}

void TangentQR::factorise(double* q_out, double* log_r) {
  // Keep the squares in range: scale by a power of two (exact) when the entries are far from 1.
  double biggest = 0;
  for (long i = 0; i < n_ * k_; ++i) biggest = std::max(biggest, std::abs(block_[i]));
  if (!std::isfinite(biggest)) throw NumericalFailure("Lyapunov QR: the tangent block is not finite");
  double log_scale = 0;
  if (biggest > 0x1p300 || (biggest < 0x1p-300 && biggest > 0)) {
    const int e = std::ilogb(biggest);
    for (long i = 0; i < n_ * k_; ++i) block_[i] = std::ldexp(block_[i], -e);
    log_scale = e * std::log(2.0);
  }
  // block = Q R (Householder, in place: R in the upper triangle, reflectors below)
  qr_rows_dispatch(block_, n_, k_, tau_.data(), r_.data(), norm_.data(), q_out);
  for (int i = 0; i < k_; ++i) {
    const double r = r_[i];
    if (!std::isfinite(r))
      throw NumericalFailure("Lyapunov QR: R(" + std::to_string(i) + "," + std::to_string(i) +
                             ") = " + format_number(r) + " (the tangent block is not finite)");
    if (!(std::abs(r) > dependence_threshold(n_) * norm_[i]))
      throw NumericalFailure("Lyapunov QR: tangent vector " + std::to_string(i + 1) +
                             " became linearly dependent on the previous ones (|R_ii| = " + format_number(std::abs(r)) +
                             ", below n eps times its norm " + format_number(norm_[i]) +
                             "); fewer exponents, or a smaller qr_every");
    log_r[i] = std::log(std::abs(r)) + log_scale;
  }
  // signs: make R_ii > 0 by flipping column i of Q, so the tangent vectors evolve continuously
  for (int c = 0; c < k_; ++c)
    if (r_[c] < 0)
      for (long i = 0; i < n_; ++i) q_out[i * k_ + c] = -q_out[i * k_ + c];
}

void random_block(double* block, long n, int k, std::uint64_t seed) {
  std::mt19937_64 engine(seed);
  // (top 53 bits) * 2^-53 - 1/2: uniform in [-1/2, 1/2), bit-identical across standard libraries
  for (long i = 0; i < n * k; ++i) block[i] = static_cast<double>(engine() >> 11) * 0x1.0p-53 - 0.5;
}

LyapunovStatistics lyapunov_statistics(const std::vector<double>& interval_logs, int k, int qr_every, int batches) {
  LyapunovStatistics st;
  const long intervals = static_cast<long>(interval_logs.size()) / k;
  const long b_count = std::min<long>(batches, intervals);
  const double periods = static_cast<double>(intervals * qr_every);
  st.batches = static_cast<int>(b_count);
  st.mean_per_period.assign(k, 0.0);
  st.batch_standard_error.assign(k, 0.0);
  st.fluctuation_bound.assign(k, 0.0);
  st.error.assign(k, 0.0);
  std::vector<double> batch_mean(static_cast<size_t>(b_count) * k, 0.0);
  for (long b = 0; b < b_count; ++b) {
    // batch b: intervals [b I / B, (b + 1) I / B)
    const long first = b * intervals / b_count, last = (b + 1) * intervals / b_count;
    for (int j = 0; j < k; ++j) {
      double sum = 0;
      for (long i = first; i < last; ++i) sum += interval_logs[i * k + j];
      batch_mean[b * k + j] = sum / static_cast<double>((last - first) * qr_every);
    }
  }
  for (int j = 0; j < k; ++j) {
    double sum = 0;
    for (long i = 0; i < intervals; ++i) sum += interval_logs[i * k + j];
    const double mean = sum / periods;
    double ss = 0;
    for (long b = 0; b < b_count; ++b) ss += (batch_mean[b * k + j] - mean) * (batch_mean[b * k + j] - mean);
    st.mean_per_period[j] = mean;
    // sd of the batch means / sqrt(B); batches of unequal length (by one interval) are treated as equal
    st.batch_standard_error[j] =
        b_count > 1 ? std::sqrt(ss / static_cast<double>(b_count - 1) / static_cast<double>(b_count)) : NAN;
    // D(i) = S(i) - i q mean, S(i) = sum of the first i interval logs (D(0) = D(I) = 0): the
    // detrended cumulative sum; its range over i = 0..I, divided by the periods, bounds a bounded
    // fluctuation's effect on the mean (header comment).
    const double per_interval = mean * qr_every;
    double s = 0, lo = 0, hi = 0;
    for (long i = 0; i < intervals; ++i) {
      s += interval_logs[i * k + j] - per_interval;  // D(i + 1)
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    st.fluctuation_bound[j] = (hi - lo) / periods;
    // error^2 = SE^2 + F^2 (header comment)
    st.error[j] = std::hypot(st.batch_standard_error[j], st.fluctuation_bound[j]);
  }
  return st;
}

void validate_lyapunov_options(const LyapunovOptions& o, long n) {
  if (o.exponents < 1 || o.exponents > n || o.exponents > kMaxTangentVectors)
    throw BadInput("`exponents = " + std::to_string(o.exponents) + "`: must be between 1 and min(" +
                   std::to_string(kMaxTangentVectors) + ", n = " + std::to_string(n) +
                   ") (only leading exponents are meant)");
  if (o.qr_every < 1) throw BadInput("`qr_every = " + std::to_string(o.qr_every) + "`: must be an integer >= 1");
  if (o.periods < 2 * static_cast<long>(o.qr_every) || o.periods % o.qr_every != 0)
    throw BadInput("`periods = " + std::to_string(o.periods) + "` must be a multiple of `qr_every = " +
                   std::to_string(o.qr_every) + "` with at least two QR intervals (for the error estimate)");
  if (o.transient < 0) throw BadInput("`transient = " + std::to_string(o.transient) + "`: must be >= 0");
  if (o.batches < 2) throw BadInput("`batches = " + std::to_string(o.batches) + "`: must be an integer >= 2");
  if (o.section_points < 0) throw BadInput("`section_points = " + std::to_string(o.section_points) + "`: must be >= 0");
}

}  // namespace delayspec
