#pragma once
// FlushSubnormals: while an object lives, this thread's floating-point unit treats subnormal
// inputs as zero and flushes subnormal results to zero (x86 SSE: MXCSR FTZ and DAZ; AArch64:
// FPCR FZ); the destructor restores the previous mode. Elsewhere it does nothing.
//
// Why: a trajectory that decays (a stable linear model started off its zero orbit, e.g. the
// Mathieu equation over thousands of periods) reaches |y| ~ 1e-308 and then stays subnormal,
// where every multiply and add costs a microcode assist of ~100 cycles: measured on the
// `lyapunov` runs of docs/benchmarks.md (N = 1000, 3000 periods), the Mathieu run took 0.22 s
// instead of 0.14 s: 47 ns per step (QR included) until its trajectory went subnormal near
// period 1060, 92 ns after. Values below 2.2e-308 carry nothing a Lyapunov run or a step map
// can use: they differ from zero by less than 1e-300 of every O(1) quantity they are added to
// (the tangent block is renormalised by every QR), so flushing them changes results by less
// than that. A decaying trajectory then stops near 1e-306, where its O(h) increments underflow,
// instead of creeping through the subnormals: a state that small is the zero state for every
// purpose of the run (its step maps differ from those at zero by ~1e-306 relative).
//
// Scope: wrap a hot loop, not a whole call that also runs user callbacks (progress), so those
// see the caller's mode. Thread-local by nature (each thread has its own control register).
#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#endif

namespace delayspec::detail {

class FlushSubnormals {
 public:
#if defined(__SSE__) || defined(__x86_64__)
  static constexpr unsigned kFlushBits = 0x8040;  // MXCSR: FTZ (bit 15) | DAZ (bit 6)
  FlushSubnormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | kFlushBits); }
  ~FlushSubnormals() { _mm_setcsr(saved_); }
#elif defined(__aarch64__)
  static constexpr unsigned long kFlushBits = 1ul << 24;  // FPCR: FZ
  FlushSubnormals() : saved_(__builtin_aarch64_get_fpcr64()) { __builtin_aarch64_set_fpcr64(saved_ | kFlushBits); }
  ~FlushSubnormals() { __builtin_aarch64_set_fpcr64(saved_); }
#else
  FlushSubnormals() = default;  // no flush mode known: subnormals are only slow, not wrong
#endif
  FlushSubnormals(const FlushSubnormals&) = delete;
  FlushSubnormals& operator=(const FlushSubnormals&) = delete;

 private:
#if defined(__SSE__) || defined(__x86_64__)
  unsigned saved_;
#elif defined(__aarch64__)
  unsigned long saved_;
#endif
};

}  // namespace delayspec::detail
