#pragma once
// Progress: count, rate and ETA of long work (sweeps, exponent runs, convergence studies,
// grids), reported on stderr.
//  * stderr is a terminal (isatty(2) and the stream is std::cerr): a bar redrawn in place,
//        sweep [##########..........]  20/40  2.1/s  ETA 9 s
//  * otherwise (a log file, a pipe, a test's stream): one line every few seconds,
//        sweep: 20/40 (50%), 2.1/s, ETA 9 s
//  * quiet (--quiet): nothing at all.
// add() is thread-safe: the workers of a parallel sweep call it directly. Printing happens on
// whichever thread crosses the reporting interval (at most one at a time, never blocking the
// others for more than one short write). Nothing is printed for work that finishes before the
// first report is due, so short runs stay silent.
//
// Example:
//     Progress progress(inv.err, "sweep", points.size(), inv.quiet);
//     parallel_for(points, [&](auto& p) { compute(p); progress.add(); });
//     progress.finish();   // "sweep: 40/40 done in 19.0 s" (only if something was printed)
#include <atomic>
#include <chrono>
#include <mutex>
#include <ostream>
#include <string>

namespace delayspec::cli {

struct ProgressOptions {
  enum class Style { automatic, bar, lines };
  Style style = Style::automatic;     // automatic: bar on a terminal, lines otherwise
  double line_interval_seconds = 5;   // lines: seconds between two reports
  double bar_interval_seconds = 0.2;  // bar: seconds between two redraws
  int bar_width = 30;
};

class Progress {
 public:
  // total <= 0: the amount of work is unknown (count and rate, no ETA).
  Progress(std::ostream& err, std::string label, long total, bool quiet, ProgressOptions options = {});
  ~Progress();  // finish()
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // count more units done; thread-safe.
  void add(long count = 1);
  // Ends the report: the bar gets its final state and a newline; in line mode a closing line.
  // Idempotent; prints only when a report was printed before.
  void finish();

  long count() const { return done_.load(std::memory_order_relaxed); }
  double elapsed_seconds() const;
  // The text of one report (without the bar's carriage return), for tests and for finish().
  std::string describe(long done, double seconds) const;

 private:
  void report(long done, double seconds, bool final);

  std::ostream& err_;
  std::string label_;
  long total_;
  bool quiet_;
  bool bar_;
  ProgressOptions options_;
  std::chrono::steady_clock::time_point start_;
  std::atomic<long> done_{0};
  std::atomic<double> next_report_seconds_;
  std::mutex print_mutex_;
  bool printed_ = false;   // guarded by print_mutex_
  bool finished_ = false;  // guarded by print_mutex_
};

// Seconds formatted for people: "9 s", "3 min 20 s", "1 h 05 min".
std::string format_duration(double seconds);

}  // namespace delayspec::cli
