#include "scene/problem/lyapunov_settings.hpp"

#include <climits>

namespace delayspec::cli {

LyapunovOptions read_lyapunov_options(Config& config, int default_exponents) {
  LyapunovOptions o;
  // Bounds: at most kMaxTangentVectors exponents (lyapunov.hpp); periods and transient at most
  // 1e9 each, so transient + periods cannot overflow; the per-interval logs (periods / qr_every
  // times exponents doubles) at most kMaxLogs = 1e8 (800 MB), checked before anything is allocated.
  constexpr long kMaxPeriods = 1'000'000'000, kMaxLogs = 100'000'000;
  o.exponents = static_cast<int>(config.get_int_in_range("exponents", default_exponents, 1, kMaxTangentVectors));
  o.periods = config.get_int_in_range("periods", o.periods, 2, kMaxPeriods);
  o.transient = config.get_int_in_range("transient", o.transient, 0, kMaxPeriods);
  o.seed = static_cast<std::uint64_t>(config.get_int_in_range("seed", 1, 0, LONG_MAX));
  o.qr_every = static_cast<int>(config.get_int_in_range("qr_every", 1, 1, kMaxPeriods));
  o.batches = static_cast<int>(config.get_int_in_range("batches", o.batches, 2, kMaxPeriods));
  if (o.periods % o.qr_every != 0)
    throw BadInput("`periods = " + std::to_string(o.periods) +
                   "` must be a multiple of `qr_every = " + std::to_string(o.qr_every) + "`");
  if (o.periods / o.qr_every > kMaxLogs / o.exponents)
    throw BadInput("`periods = " + std::to_string(o.periods) + "`: with `exponents = " + std::to_string(o.exponents) +
                   "` and `qr_every = " + std::to_string(o.qr_every) +
                   "` the run would keep more than 1e8 logarithms (periods / qr_every * exponents <= 1e8)");
  return o;
}

LyapunovResult run_lyapunov(const Problem& problem, const LyapunovOptions& options) {
  return problem.analyses->lyapunov(problem.map_settings(), options);
}

}  // namespace delayspec::cli
