#include "delayspec/lyapunov.hpp"

#include <cmath>
#include <random>
#include <string>

#include <Eigen/QR>

namespace delayspec {

namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using BlockRef = Eigen::Ref<RowMajorMatrix>;

// HouseholderQR bound to the block's memory: the in-place constructor factorises it, and
// refactorise() runs Eigen's in-place factorisation again on whatever the block now holds,
// without the copy compute() would make.
class InPlaceQR : public Eigen::HouseholderQR<BlockRef> {
 public:
  explicit InPlaceQR(BlockRef& block) : Eigen::HouseholderQR<BlockRef>(block) {}
  void refactorise() { this->computeInPlace(); }
};

}  // namespace

struct TangentQR::Impl {
  Eigen::Map<RowMajorMatrix> block_map;
  BlockRef block_ref;
  InPlaceQR qr;
  Eigen::Matrix<double, 1, Eigen::Dynamic> workspace;
  bool fresh = true;  // the constructor has just factorised the block
  Impl(double* block, long n, int k)
      : block_map(block, n, k), block_ref(block_map), qr(block_ref), workspace(k) {}
};

TangentQR::TangentQR(double* block, long n, int k) : n_(n), k_(k) {
  // The constructor factorises whatever the block holds; make that well defined.
  std::fill(block, block + n * k, 0.0);
  impl_ = std::make_unique<Impl>(block, n, k);
}

TangentQR::~TangentQR() = default;

void TangentQR::factorise(double* q_out, double* log_r) {
  // block = Q R (Householder, in place: R in the upper triangle, reflectors below)
  impl_->qr.refactorise();
  const auto& qr_matrix = impl_->qr.matrixQR();
  for (int i = 0; i < k_; ++i) {
    const double r = qr_matrix(i, i);
    if (!std::isfinite(r) || r == 0)
      throw NumericalFailure("Lyapunov QR: R(" + std::to_string(i) + "," + std::to_string(i) + ") = " +
                             format_number(r) +
                             (std::isfinite(r) ? " (tangent vectors became linearly dependent)"
                                               : " (the tangent block is not finite)"));
    log_r[i] = std::log(std::abs(r));
  }
  // Q = H_1 ... H_k [I_k; 0], formed by applying the reflectors to the first k unit vectors
  Eigen::Map<RowMajorMatrix> q(q_out, n_, k_);
  q.setZero();
  q.topRows(k_).setIdentity();
  // (inputIsIdentity = false: Eigen's identity shortcut assumes a square destination)
  impl_->qr.householderQ().applyThisOnTheLeft(q, impl_->workspace, false);
  // signs: make R_ii > 0 by flipping column i of Q, so the tangent vectors evolve continuously
  for (int i = 0; i < k_; ++i)
    if (qr_matrix(i, i) < 0) q.col(i) *= -1;
}

void random_block(double* block, long n, int k, std::uint64_t seed) {
  std::mt19937_64 engine(seed);
  // (top 53 bits) * 2^-53 - 1/2: uniform in [-1/2, 1/2), bit-identical across standard libraries
  for (long i = 0; i < n * k; ++i) block[i] = static_cast<double>(engine() >> 11) * 0x1.0p-53 - 0.5;
}

void batch_statistics(const std::vector<double>& interval_logs, int k, int qr_every, int batches,
                      std::vector<double>& mean_per_period, std::vector<double>& standard_error, int& batches_used) {
  const long intervals = static_cast<long>(interval_logs.size()) / k;
  const long b_count = std::min<long>(batches, intervals);
  batches_used = static_cast<int>(b_count);
  mean_per_period.assign(k, 0.0);
  standard_error.assign(k, 0.0);
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
    const double mean = sum / static_cast<double>(intervals * qr_every);
    double ss = 0;
    for (long b = 0; b < b_count; ++b) ss += (batch_mean[b * k + j] - mean) * (batch_mean[b * k + j] - mean);
    mean_per_period[j] = mean;
    // sd of the batch means / sqrt(B); batches of unequal length (by one interval) are treated as equal
    standard_error[j] = b_count > 1 ? std::sqrt(ss / static_cast<double>(b_count - 1) / static_cast<double>(b_count)) : NAN;
  }
}

void validate_lyapunov_options(const LyapunovOptions& o, long n) {
  if (o.exponents < 1 || o.exponents > n)
    throw BadInput("`exponents = " + std::to_string(o.exponents) + "`: must be between 1 and the dimension n = " +
                   std::to_string(n));
  if (o.qr_every < 1) throw BadInput("`qr_every = " + std::to_string(o.qr_every) + "`: must be an integer >= 1");
  if (o.periods < 2 * static_cast<long>(o.qr_every) || o.periods % o.qr_every != 0)
    throw BadInput("`periods = " + std::to_string(o.periods) + "` must be a multiple of `qr_every = " +
                   std::to_string(o.qr_every) + "` with at least two QR intervals (for the error estimate)");
  if (o.transient < 0) throw BadInput("`transient = " + std::to_string(o.transient) + "`: must be >= 0");
  if (o.batches < 2) throw BadInput("`batches = " + std::to_string(o.batches) + "`: must be an integer >= 2");
  if (o.section_points < 0)
    throw BadInput("`section_points = " + std::to_string(o.section_points) + "`: must be >= 0");
}

}  // namespace delayspec
