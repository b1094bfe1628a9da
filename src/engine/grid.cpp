#include "delayspec/grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "delayspec/errors.hpp"

namespace delayspec {

namespace {

constexpr long kMaxSteps = 2'000'000'000L / 8;  // keeps every block index far inside int

// Integer p/q (q <= 64) equal to x to within 1e-12 relative, or q = 0 when there is none.
// p is at most kMaxSteps q: an aligned grid has N q / p >= 1 steps per period with N <= kMaxSteps,
// so a larger p is of no use, and the bound keeps the conversion to long defined (tau / T = 1e300
// would otherwise be cast to long: undefined behaviour, seen as -9223372036854775808 in messages).
struct Ratio {
  long p = 0, q = 0;
};
Ratio rational_approximation(double x) {
  for (long q = 1; q <= 64; ++q) {
    double p = std::round(x * static_cast<double>(q));
    if (p >= 1 && p <= static_cast<double>(kMaxSteps * q) && std::abs(x * static_cast<double>(q) - p) <= 1e-12 * p)
      return {static_cast<long>(p), q};
  }
  return {};
}

// tau / h = m + theta with theta in [0, 1), snapped to a whole number of steps within 1e-12 (the
// one rule of where a delay falls between grid nodes).
HistoryGrid::DelayPosition position_on_grid(double tau, double h) {
  const double ratio = tau / h;
  double m = std::floor(ratio), theta = ratio - m;
  if (theta > 1 - 1e-12) m += 1, theta = 0;  // tau is a whole number of steps after all
  if (theta < 1e-12) theta = 0;
  return {tau, static_cast<int>(std::min(m, static_cast<double>(kMaxSteps))), theta};
}

// Steps per piece of a pattern of n steps (header of grid.hpp): halved while n / 2 keeps at least
// kMinPatternSteps and a step per piece, so that allocation(2 n) = 2 allocation(n); at the base,
// the largest-remainder rule on the ideal counts n L_i / P with at least one step per piece.
std::vector<int> allocate_steps(const std::vector<double>& lengths, double pattern, long n) {
  const long pieces = static_cast<long>(lengths.size());
  if (n % 2 == 0 && n / 2 >= std::max<long>(kMinPatternSteps, pieces)) {
    std::vector<int> half = allocate_steps(lengths, pattern, n / 2);
    for (int& c : half) c *= 2;
    return half;
  }
  std::vector<int> count(lengths.size());
  std::vector<std::pair<double, size_t>> remainder;  // (fractional part, piece)
  long total = 0;
  for (size_t i = 0; i < lengths.size(); ++i) {
    const double ideal = static_cast<double>(n) * lengths[i] / pattern;
    count[i] = std::max(1, static_cast<int>(std::floor(ideal)));
    remainder.emplace_back(ideal - std::floor(ideal), i);
    total += count[i];
  }
  // the steps left to the largest remainders (ties to the earlier piece); steps too many (a piece
  // raised to its one step) taken from the pieces with the most, the longest first
  std::stable_sort(remainder.begin(), remainder.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  for (size_t r = 0; total < n; ++r, ++total) ++count[remainder[r % remainder.size()].second];
  while (total > n) {
    const size_t most = static_cast<size_t>(std::max_element(count.begin(), count.end()) - count.begin());
    --count[most];
    --total;
  }
  return count;
}

// Lays the pieces of the aligned grid g (header of grid.hpp) with q patterns per period of n
// steps each: g.breakpoints, g.piece_steps, g.pattern and the K_1 + 1 node times.
void lay_breakpoints(HistoryGrid& g, const GridBreaks& breaks, long q, long n) {
  const double P = g.period / static_cast<double>(q);
  const double merge = 1e-12 * P;  // one time computed twice with rounding (time_switch_step.hpp: 64 eps)
  std::vector<double> starts{0.0};
  for (double t : breaks.times) {
    if (!std::isfinite(t)) throw BadInput("a time switch of the model is " + format_number(t));
    double b = std::fmod(t, P);
    if (b < 0) b += P;
    if (b > P - merge) b = 0;
    starts.push_back(b);
  }
  std::sort(starts.begin(), starts.end());
  std::vector<double> kept;
  for (double b : starts)
    if (kept.empty() || b - kept.back() > merge) kept.push_back(b);
  std::vector<double> lengths;
  for (size_t i = 0; i < kept.size(); ++i) lengths.push_back((i + 1 < kept.size() ? kept[i + 1] : P) - kept[i]);
  const long pieces = static_cast<long>(kept.size());
  std::vector<int> counts = breaks.piece_steps;
  if (counts.empty()) {
    if (n < pieces)
      throw BadInput("`N = " + std::to_string(g.N) + "`: the grid aligned with the model's " +
                     std::to_string(pieces) + " pieces between time switches needs a step in each (N >= " +
                     std::to_string(pieces * (g.N / n)) + "), or `grid = uniform`");
    counts = allocate_steps(lengths, P, n);
  } else {
    long sum = 0;
    for (int c : counts) sum += c;
    if (static_cast<long>(counts.size()) != pieces || sum != n ||
        std::any_of(counts.begin(), counts.end(), [](int c) { return c < 1; }))
      throw BadInput("the grid's allocation (" + std::to_string(counts.size()) + " pieces, " + std::to_string(sum) +
                     " steps) does not fit " + std::to_string(pieces) + " pieces between time switches and " +
                     std::to_string(n) + " steps per pattern at N = " + std::to_string(g.N));
  }
  g.breakpoints = kept;
  g.piece_steps = counts;
  g.pattern = P;
  g.nodes.clear();
  g.nodes.reserve(static_cast<size_t>(q * n + 1));
  for (long k = 0; k < q; ++k)
    for (size_t i = 0; i < kept.size(); ++i)
      for (int j = 0; j < counts[i]; ++j)
        g.nodes.push_back(static_cast<double>(k) * P + kept[i] + lengths[i] * j / counts[i]);
  g.nodes.push_back(g.period);
}

}  // namespace

std::string HistoryGrid::describe() const {
  std::string text = "N=" + std::to_string(N) + " h=" + format_number(h) + " K=" + std::to_string(K) +
                     " M=" + std::to_string(M);
  if (has_breakpoints()) text.append(" aligned with ").append(std::to_string(breakpoints.size())).append(" pieces");
  if (delays.empty())
    return text + (aligned() ? " (aligned delay)" : " (fractional delay, theta=" + format_number(theta) + ")");
  text += " (" + std::to_string(delays.size()) + " delays at m + theta steps:";
  for (const DelayPosition& p : delays) {  // (append: GCC 12 warns falsely on "+" + string, -Wrestrict)
    text.append(" ").append(std::to_string(p.m));
    if (p.theta != 0) text.append("+").append(format_number(p.theta));
  }
  return text + ")";
}

std::vector<double> HistoryGrid::delay_values() const {
  if (delays.empty()) return {tau};
  std::vector<double> out;
  for (const DelayPosition& p : delays) out.push_back(p.tau);
  return out;
}

HistoryGrid make_grid(const std::vector<double>& taus, double period, int N, int periods_per_map,
                      const std::vector<std::string>& names, const GridBreaks& breaks) {
  if (taus.empty()) throw BadInput("make_grid: no delay given");
  const auto name = [&](size_t i) {
    return names.size() == taus.size() ? names[i]
                                       : "delay " + std::to_string(i + 1) + " of " + std::to_string(taus.size());
  };
  for (size_t i = 0; i < taus.size(); ++i)
    if (!(std::isfinite(taus[i]) && taus[i] > 0))
      throw BadInput(name(i) + " is " + format_number(taus[i]) + ": a delay must be positive and finite");
  const size_t longest = static_cast<size_t>(std::max_element(taus.begin(), taus.end()) - taus.begin());
  HistoryGrid g = make_grid(taus[longest], period, N, periods_per_map, taus.size() == 1 ? breaks : GridBreaks{});
  if (taus.size() == 1) return g;
  for (size_t i = 0; i < taus.size(); ++i) {
    HistoryGrid::DelayPosition p{taus[i], g.m, g.theta};
    if (i != longest) {
      p = position_on_grid(taus[i], g.h);  // tau_i = (m_i + theta_i) h, snapped as make_grid snaps tau
      if (p.m < 1)
        throw BadInput("`N = " + std::to_string(N) + "`: " + name(i) + " = " + format_number(taus[i]) +
                       " is shorter than one step h = " + format_number(g.h) +
                       " (N steps per the longest delay, " + format_number(taus[longest]) + "); increase N");
    }
    g.delays.push_back(p);
  }
  return g;
}

HistoryGrid make_grid(double tau, double period, int N, int periods_per_map, const GridBreaks& breaks) {
  require_positive("tau", tau);
  require_positive("period", period);
  if (N < 1) throw BadInput("`N = " + std::to_string(N) + "`: must be an integer >= 1");
  if (periods_per_map < 1)
    throw BadInput("`orbit_period = " + std::to_string(periods_per_map) + "`: must be an integer >= 1");

  HistoryGrid g;
  g.N = N;
  g.tau = tau;
  g.period = period;
  g.periods_per_map = periods_per_map;

  Ratio r = rational_approximation(tau / period);  // tau / T = p / q
  if (r.q > 0) {
    // Aligned: h = tau / N, steps per period N T / tau = N q / p must be an integer.
    if ((static_cast<long>(N) * r.q) % r.p != 0)
      throw BadInput("`N = " + std::to_string(N) + "`: tau/T = " + std::to_string(r.p) + "/" + std::to_string(r.q) +
                     " needs N divisible by " + std::to_string(r.p) + " so that a period is a whole number of steps");
    long k1 = static_cast<long>(N) * r.q / r.p;
    if (k1 * periods_per_map > kMaxSteps || N > kMaxSteps)
      throw BadInput("`N = " + std::to_string(N) + "`: too many steps per map");
    g.h = tau / N;
    g.steps_per_period = static_cast<int>(k1);
    g.m = N;
    g.theta = 0;
    g.M = N;
    if (!breaks.times.empty()) lay_breakpoints(g, breaks, r.q, N / r.p);  // p | N: N q / p whole, gcd(p, q) = 1
  } else {
    // Fractional: h = T / K_1, tau = (m + theta) h.
    double k1 = std::round(static_cast<double>(N) * period / tau);
    if (k1 < 1) k1 = 1;
    if (k1 * periods_per_map > static_cast<double>(kMaxSteps))
      throw BadInput("`N = " + std::to_string(N) + "`: too many steps per map (N T / tau = " + format_number(k1) +
                     " steps per period with tau = " + format_number(tau) + ", T = " + format_number(period) + ")");
    g.steps_per_period = static_cast<int>(k1);
    g.h = period / k1;
    double ratio = tau / g.h;
    // The history holds tau / h steps: checked before the conversion to int below.
    if (!(ratio <= static_cast<double>(kMaxSteps)))
      throw BadInput("`tau = " + format_number(tau) + "`: the delay spans " + format_number(ratio) +
                     " steps of h = " + format_number(g.h) + " (T = " + format_number(period) + " in " +
                     format_number(k1) + " steps at N = " + std::to_string(N) + "), more than the " +
                     std::to_string(kMaxSteps) + " steps a history can hold; reduce tau or N");
    const HistoryGrid::DelayPosition at = position_on_grid(tau, g.h);
    if (at.m < 1)
      throw BadInput("`N = " + std::to_string(N) + "`: the delay tau = " + format_number(tau) +
                     " is shorter than one step h = " + format_number(g.h) + "; increase N");
    g.m = at.m;
    g.theta = at.theta;
    g.M = g.theta > 0 ? g.m + 1 : g.m;
  }
  g.K = g.steps_per_period * periods_per_map;
  if (!breaks.region1.empty()) {
    if (!g.has_breakpoints())
      throw BadInput("make_grid: fixed regions need a grid aligned with their ends (one aligned delay)");
    const double span = g.period * periods_per_map;
    g.step_regions.resize(static_cast<size_t>(g.K));
    for (long l = 0; l < g.K; ++l) {
      const double mid = g.node_time(l) + 0.5 * g.step_size(l);
      bool inside = false;
      for (const auto& [in, out] : breaks.region1) {
        if (!(in >= 0 && in < span && out >= 0 && out <= span))
          throw BadInput("make_grid: a region-1 interval [" + format_number(in) + ", " + format_number(out) +
                         ") outside the map's time [0, " + format_number(span) + ")");
        inside = inside || (in <= out ? (mid >= in && mid < out) : (mid >= in || mid < out));
      }
      g.step_regions[static_cast<size_t>(l)] = static_cast<signed char>(inside ? 1 : 2);
    }
  }
  return g;
}

HistoryGrid make_grid_with_steps(const std::vector<double>& taus, double period, int steps_per_period,
                                 int periods_per_map) {
  require_positive("period", period);
  if (taus.empty()) throw BadInput("make_grid_with_steps: no delay given");
  if (steps_per_period < 1 || static_cast<long>(steps_per_period) * periods_per_map > kMaxSteps)
    throw BadInput(std::string("steps per period ")
                       .append(std::to_string(steps_per_period))
                       .append(": must be between 1 and ")
                       .append(std::to_string(kMaxSteps / std::max(periods_per_map, 1))));
  HistoryGrid g;
  g.period = period;
  g.periods_per_map = periods_per_map;
  g.steps_per_period = steps_per_period;
  g.K = steps_per_period * periods_per_map;
  g.h = period / steps_per_period;
  size_t longest = 0;
  for (size_t i = 0; i < taus.size(); ++i) {
    // (append, not "delay " + string: GCC 12 warns falsely on that, -Wrestrict)
    const std::string delay = std::string("delay ").append(std::to_string(i + 1));
    if (!(std::isfinite(taus[i]) && taus[i] > 0 && taus[i] / g.h <= static_cast<double>(kMaxSteps)))
      throw BadInput(delay + " is " + format_number(taus[i]) +
                     ": must be positive, finite and at most " + std::to_string(kMaxSteps) + " steps");
    const HistoryGrid::DelayPosition p = position_on_grid(taus[i], g.h);
    if (p.m < 1)
      throw BadInput(delay + " = " + format_number(taus[i]) +
                     " is shorter than one step h = " + format_number(g.h) + " (" + std::to_string(steps_per_period) +
                     " steps per period " + format_number(period) + ")");
    if (taus[i] > taus[longest]) longest = i;
    if (taus.size() > 1) g.delays.push_back(p);
  }
  const HistoryGrid::DelayPosition at = position_on_grid(taus[longest], g.h);
  g.tau = at.tau;
  g.m = at.m;
  g.theta = at.theta;
  g.M = g.theta > 0 ? g.m + 1 : g.m;
  g.N = g.m;  // steps per the longest delay, as laid
  return g;
}

HistoryGrid regrid(const HistoryGrid& g, int N) {
  GridBreaks breaks;
  breaks.times = g.breakpoints;
  return make_grid(g.delay_values(), g.period, N, g.periods_per_map, {}, breaks);
}

}  // namespace delayspec
