#include "delayspec/lyapunov.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

namespace delayspec {

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
