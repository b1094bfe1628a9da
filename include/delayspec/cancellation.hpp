#pragma once
// Cooperative cancellation of long runs. A front end that can be interrupted (the Python module:
// Ctrl-C -> KeyboardInterrupt) installs a check for the thread that runs the work
// (CancellationScope); the library calls throw_if_cancelled() between periods (each application
// of the stroboscopic map or of the monodromy operator, each period of an exponent or simulation
// run), which throws Cancelled once the check says so. Threads that work for another (the points
// of a parallel sweep) take over its check. Without a check (the CLI: SIGINT ends the process,
// the result files are atomic) a call costs one thread-local load.
//
// Cancelled is deliberately not a std::exception: no handler that records a failed point
// (NumericalFailure) or reports an internal error (std::exception) may swallow it.

namespace delayspec {

struct Cancelled {};

class CancellationCheck {
 public:
  virtual ~CancellationCheck() = default;
  // True once the work should stop; called from any thread that works under this check.
  virtual bool requested() = 0;
};

// The check of the calling thread; nullptr when none is installed.
CancellationCheck* current_cancellation_check() noexcept;

// Installs `check` (may be nullptr) for the calling thread until the scope ends.
class CancellationScope {
 public:
  explicit CancellationScope(CancellationCheck* check) noexcept;
  ~CancellationScope();
  CancellationScope(const CancellationScope&) = delete;
  CancellationScope& operator=(const CancellationScope&) = delete;

 private:
  CancellationCheck* previous_;
};

// Throws Cancelled when the calling thread's check requests it.
inline void throw_if_cancelled() {
  if (CancellationCheck* check = current_cancellation_check(); check && check->requested()) throw Cancelled{};
}

}  // namespace delayspec
