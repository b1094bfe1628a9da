#pragma once
// sin and cos remembered for the last two arguments on this thread, for a model's forcing term.
//
// Why: a trapezoid step evaluates the field at its two nodes several times (the implicit step,
// the event test's slopes, and the next step's left node is this step's right node), and GCC
// cannot share a sin between calls that are not inlined into one function. Measured with perf on
// `lyapunov` of the impact model (N = 1000, 2 exponents): sin was 28 % of the run, four calls
// per step; with the memo, one. The values are those of std::sin / std::cos (bit for bit): a
// hit returns what the same call returned before.
//
// Thread-local, so concurrent maps (threads of a chart, two Python threads) never share it.
#include <cmath>

namespace delayspec::detail {

enum class Trig { sin, cos };

template <Trig fn>
double remembered(double x) {
  thread_local double argument[2] = {NAN, NAN}, value[2] = {0, 0};
  thread_local int oldest = 0;
  if (x == argument[0]) return value[0];  // (NaN never matches: it is recomputed)
  if (x == argument[1]) return value[1];
  const double v = fn == Trig::sin ? std::sin(x) : std::cos(x);
  argument[oldest] = x;
  value[oldest] = v;
  oldest ^= 1;
  return v;
}

inline double remembered_sin(double x) { return remembered<Trig::sin>(x); }
inline double remembered_cos(double x) { return remembered<Trig::cos>(x); }

}  // namespace delayspec::detail
