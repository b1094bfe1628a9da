#include "delayspec/periodic_orbit.hpp"

#include <algorithm>
#include <string>

#include "delayspec/errors.hpp"

namespace delayspec {

std::string to_string(OrbitFoundBy method) {
  switch (method) {
    case OrbitFoundBy::simulate: return "simulate";
    case OrbitFoundBy::newton: return "newton";
    case OrbitFoundBy::shooting: return "shooting";
    case OrbitFoundBy::zero: return "zero";
  }
  return "?";
}

Eigen::VectorXd prolong_periodic_sequence(const Eigen::VectorXd& x, int d, long K_to) {
  if (d < 1 || K_to < 1 || x.size() == 0 || x.size() % d != 0)
    throw BadInput("prolong_periodic_sequence: " + std::to_string(x.size()) + " entries of dimension " +
                   std::to_string(d) + " to " + std::to_string(K_to) + " states");
  const long K_from = x.size() / d;
  auto u = [&](long i) { return x.segment(d * (((i % K_from) + K_from) % K_from), d); };  // u_{i+K} = u_i
  Eigen::VectorXd y(static_cast<long>(d) * K_to);
  for (long l = 0; l < K_to; ++l) {
    // position of l h_to on the old grid: s = l K_from / K_to (same map period K h)
    const double s = static_cast<double>(l) * K_from / K_to;
    const long i = std::min(static_cast<long>(s), K_from - 1);
    const double w = s - i;
    if (K_from < 4) {  // too few states for a cubic: linear, u(s) = (1 - w) u_i + w u_{i+1}
      y.segment(d * l, d) = (1 - w) * u(i) + w * u(i + 1);
      continue;
    }
    // 4-point Lagrange cubic through u_{i-1}, u_i, u_{i+1}, u_{i+2} (weights at offset w in [0, 1))
    const double cm = -w * (w - 1) * (w - 2) / 6, c0 = (w + 1) * (w - 1) * (w - 2) / 2, c1 = -(w + 1) * w * (w - 2) / 2,
                 c2 = (w + 1) * w * (w - 1) / 6;
    y.segment(d * l, d) = cm * u(i - 1) + c0 * u(i) + c1 * u(i + 1) + c2 * u(i + 2);
  }
  return y;
}

Eigen::VectorXd prolong_periodic_sequence(const Eigen::VectorXd& x, int d, const HistoryGrid& from,
                                          const HistoryGrid& to) {
  if (!from.has_breakpoints() && !to.has_breakpoints()) return prolong_periodic_sequence(x, d, to.K);
  if (d < 1 || x.size() != static_cast<long>(d) * from.K)
    throw BadInput("prolong_periodic_sequence: " + std::to_string(x.size()) + " entries of dimension " +
                   std::to_string(d) + " for a grid of " + std::to_string(from.K) + " states");
  const long K_from = from.K;
  const double span = static_cast<double>(from.periods_per_map) * from.period;  // the map's time
  Eigen::VectorXd y(static_cast<long>(d) * to.K);
  long i = 0;  // the state of `from` at or before t (t increases with l)
  for (long l = 0; l < to.K; ++l) {
    const double t = to.node_time(l);
    while (i + 1 < K_from && from.node_time(i + 1) <= t) ++i;
    const double t0 = from.node_time(i), t1 = i + 1 < K_from ? from.node_time(i + 1) : span;
    const double w = std::clamp((t - t0) / (t1 - t0), 0.0, 1.0);
    y.segment(d * l, d) = (1 - w) * x.segment(d * i, d) + w * x.segment(d * ((i + 1) % K_from), d);
  }
  return y;
}

}  // namespace delayspec
