#pragma once
// sin and cos remembered for the arguments seen recently on this thread, for a model's forcing term.
//
// Why: a trapezoid step evaluates the field at its two nodes several times (the implicit step,
// the event test's slopes, and the next step's left node is this step's right node), and GCC
// cannot share a sin between calls that are not inlined into one function. Measured with perf on
// `lyapunov` of the impact model (N = 1000, 2 exponents): sin was 28 % of the run, four calls
// per step; remembering the last two arguments left about one. The step times repeat every
// forcing period (step l starts at (l mod K_1) h), so a table of the last few thousand
// arguments (src/remembered_trig.cpp: 2-way set-associative, 2^14 entries per function) answers
// nearly every call after the first period for N up to a few thousand: measured on the Mathieu
// model, 2 cos per step (15 ns) became 2 lookups (3 ns). The values are those of std::sin /
// std::cos (bit for bit): a hit returns what the same call with the same argument bits returned
// before.
//
// Thread-local, so concurrent maps (threads of a chart, two Python threads) never share it.
// One definition, in the library (src/remembered_trig.cpp), shared by the built-in models and
// the models compiled at run time from a scene's equations: the memo's thread-local storage is
// the library's, in the initial-exec model (one load, no __tls_get_addr call per access, which
// an object loaded with dlopen would pay: measured 1.39 s against 1.25 s for the impact
// equations' Lyapunov run, bench_equations), and there is one copy of it per process however
// many equation models are loaded.

namespace delayspec::detail {

// [[gnu::const]]: the result depends on x alone (the memo is not observable), so GCC may share
// one call between the f and A of a node, as it shares std::cos under -fno-math-errno.
[[gnu::const]] double remembered_sin(double x);
[[gnu::const]] double remembered_cos(double x);

}  // namespace delayspec::detail
