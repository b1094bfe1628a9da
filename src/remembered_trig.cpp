#include "delayspec/detail/remembered_trig.hpp"

#include <cmath>

namespace delayspec::detail {

namespace {

enum class Trig { sin, cos };

// The last two arguments and values of one function on this thread. initial-exec: the library
// is loaded at start-up or once with the Python module; its few bytes of thread-local storage
// fit the static TLS block either way.
template <Trig fn>
double remembered(double x) {
  __attribute__((tls_model("initial-exec"))) thread_local double argument[2] = {NAN, NAN}, value[2] = {0, 0};
  __attribute__((tls_model("initial-exec"))) thread_local int oldest = 0;
  if (x == argument[0]) return value[0];  // (NaN never matches: it is recomputed)
  if (x == argument[1]) return value[1];
  const double v = fn == Trig::sin ? std::sin(x) : std::cos(x);
  argument[oldest] = x;
  value[oldest] = v;
  oldest ^= 1;
  return v;
}

}  // namespace

double remembered_sin(double x) { return remembered<Trig::sin>(x); }
double remembered_cos(double x) { return remembered<Trig::cos>(x); }

}  // namespace delayspec::detail
