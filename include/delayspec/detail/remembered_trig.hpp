#pragma once
// sin and cos remembered for the arguments seen recently on this thread, for a model's forcing term.
//
// Why: a trapezoid step evaluates the field at its two nodes several times (the implicit step,
// the event test's slopes, and the next step's left node is this step's right node), and GCC
// cannot share a sin between calls that are not inlined into one function. Measured with perf on
// `lyapunov` of the impact model (N = 1000, 2 exponents): sin was 28 % of the run, four calls
// per step; remembering the last two arguments left about one. The step times repeat every
// forcing period (step l starts at (l mod K_1) h), so a table of the last few thousand
// arguments (2-way set-associative, 2^13 sets per function) answers nearly every call after the
// first period for N up to a few thousand: measured on the Mathieu model, 2 cos per step (15 ns)
// became 2 lookups (3 ns). The values are those of std::sin / std::cos (bit for bit): a hit
// returns what the same call with the same argument bits returned before.
//
// The lookup of the newer entry of a set is inline (below); everything else (the older entry,
// a miss, the table's creation) is the call remembered_trig_miss in src/engine/remembered_trig.cpp.
// Why inline: a call into the library spills the live xmm registers; inline, the impact
// model's Lyapunov step went from 41 to 34 ns (bench_lyapunov, docs/benchmarks.md "Eighth
// sitting"). GCC shares a [[gnu::const]] call between f and A of a node but not the inline
// lookups (a miss in between may change the table): Mathieu makes four lookups per step where
// it made two calls, and gained 0.6 ns of 18.
//
// Thread-local, so concurrent maps (threads of a chart, two Python threads) never share it.
// One definition of the tables, in the library, shared by the built-in models and the models
// compiled at run time from a scene's equations: the pointers are the library's thread-local
// variables in the initial-exec model (one load, no __tls_get_addr call per access, which an
// object loaded with dlopen would pay: measured 1.39 s against 1.25 s for the impact equations'
// Lyapunov run, bench_equations), and there is one copy of them per process however many
// equation models are loaded.

#include <bit>
#include <cstdint>

namespace delayspec::detail {

// A set of the table: two (argument bits, value) entries, the most recently used first.
// 32 bytes, aligned: one cache line access per lookup.
struct alignas(32) TrigSet {
  std::uint64_t argument[2];
  double value[2];
};
inline constexpr int kTrigSetBits = 13;
enum class Trig { sin, cos };

// The calling thread's tables, indexed by Trig; null until the thread's first miss. `__thread`
// (trivially constructed, so no C++ thread_local wrapper call) and initial-exec (see above).
extern __thread TrigSet* trig_sets[2] __attribute__((tls_model("initial-exec")));

// The set an argument's bits map to: Fibonacci hashing (the top bits of bits * 2^64 / golden
// ratio spread neighbouring arguments).
inline std::uint64_t trig_set_index(std::uint64_t bits) {
  return (bits * 0x9e3779b97f4a7c15ull) >> (64 - kTrigSetBits);
}

// The lookup past the newer entry: the older entry, a miss (std::sin / std::cos, stored), or
// the thread's first call (allocates its table).
double remembered_trig_miss(Trig fn, double x);

template <Trig fn>
[[gnu::always_inline]] inline double remembered_trig(double x) {
  const std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
  if (const TrigSet* sets = trig_sets[static_cast<int>(fn)]) {
    const TrigSet& s = sets[trig_set_index(bits)];
    if (bits == s.argument[0]) return s.value[0];
  }
  return remembered_trig_miss(fn, x);
}

// [[gnu::const]]: the result depends on x alone (the memo is not observable), so GCC may share
// one call between the f and A of a node, as it shares std::cos under -fno-math-errno.
[[gnu::const]] inline double remembered_sin(double x) { return remembered_trig<Trig::sin>(x); }
[[gnu::const]] inline double remembered_cos(double x) { return remembered_trig<Trig::cos>(x); }

}  // namespace delayspec::detail
