#pragma once
// MemoryProbe: the peak resident memory a piece of work adds, measured per piece (Linux).
// getrusage's ru_maxrss is process-wide and never decreases, so it cannot attribute memory to
// one row of a benchmark. Instead, at construction: memory malloc holds but no longer uses is
// returned to the system (malloc_trim), the kernel's peak-RSS mark is reset (writing "5" to
// /proc/self/clear_refs, Linux >= 4.0) and the current RSS is read (VmRSS); peak_bytes() is then
// VmHWM - that baseline: what the work added at its peak. Caveat: a work that reuses memory
// already resident at the start (freed but not trimmable) is under-counted by that amount.
// When /proc is not available, available() is false and peak_bytes() is -1.
namespace delayspec::cli {

class MemoryProbe {
 public:
  MemoryProbe();
  bool available() const { return available_; }
  long peak_bytes() const;  // since construction; -1 when not available

 private:
  bool available_ = false;
  long baseline_ = 0;
};

}  // namespace delayspec::cli
