#include "scene/output/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

namespace delayspec::cli {

namespace {

bool stderr_is_terminal(const std::ostream& err) { return &err == &std::cerr && ::isatty(STDERR_FILENO) == 1; }

std::string format_rate(double per_second) {
  char buf[32];
  if (per_second >= 100) std::snprintf(buf, sizeof buf, "%.0f/s", per_second);
  else if (per_second >= 1) std::snprintf(buf, sizeof buf, "%.1f/s", per_second);
  else std::snprintf(buf, sizeof buf, "%.2f/s", per_second);
  return buf;
}

}  // namespace

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  char buf[48];
  if (seconds < 10) std::snprintf(buf, sizeof buf, "%.1f s", seconds);
  else if (seconds < 60) std::snprintf(buf, sizeof buf, "%.0f s", seconds);
  else if (seconds < 3600)
    std::snprintf(buf, sizeof buf, "%d min %02d s", static_cast<int>(seconds / 60), static_cast<int>(seconds) % 60);
  else
    std::snprintf(buf, sizeof buf, "%d h %02d min", static_cast<int>(seconds / 3600),
                  static_cast<int>(seconds / 60) % 60);
  return buf;
}

Progress::Progress(std::ostream& err, std::string label, long total, bool quiet, ProgressOptions options)
    : err_(err),
      label_(std::move(label)),
      total_(total),
      quiet_(quiet),
      bar_(options.style == ProgressOptions::Style::bar ||
           (options.style == ProgressOptions::Style::automatic && stderr_is_terminal(err))),
      options_(options),
      start_(std::chrono::steady_clock::now()),
      next_report_seconds_(bar_ ? options.bar_interval_seconds : options.line_interval_seconds) {}

Progress::~Progress() { finish(); }

double Progress::elapsed_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

std::string Progress::describe(long done, double seconds) const {
  const double rate = seconds > 0 ? done / seconds : 0;
  std::ostringstream text;  // (a stream, not operator+: GCC 12 warns falsely on string concatenation)
  if (bar_) {
    text << label_ << " [";
    if (total_ > 0) {
      const int filled = static_cast<int>(std::min<long>(done, total_) * options_.bar_width / total_);
      text << std::string(filled, '#') << std::string(options_.bar_width - filled, '.');
    } else {
      text << std::string(options_.bar_width, '?');
    }
    text << "]  " << done;
    if (total_ > 0) text << "/" << total_;
    text << "  " << format_rate(rate);
  } else {
    text << label_ << ": " << done;
    if (total_ > 0) text << "/" << total_ << " (" << done * 100 / total_ << "%)";
    text << ", " << format_rate(rate);
  }
  // ETA = remaining / mean rate since the start.
  if (total_ > 0 && done < total_ && rate > 0)
    text << (bar_ ? "  ETA " : ", ETA ") << format_duration((total_ - done) / rate);
  return text.str();
}

void Progress::add(long count) {
  if (quiet_) return;
  const long done = done_.fetch_add(count, std::memory_order_relaxed) + count;
  if (total_ > 0 && done >= total_) return;  // the last report is finish()'s
  const double seconds = elapsed_seconds();
  double due = next_report_seconds_.load(std::memory_order_relaxed);
  if (seconds < due) return;
  // One thread wins the right to report this interval; the others go back to work.
  const double next = seconds + (bar_ ? options_.bar_interval_seconds : options_.line_interval_seconds);
  if (!next_report_seconds_.compare_exchange_strong(due, next, std::memory_order_relaxed)) return;
  report(done, seconds, false);
}

void Progress::report(long done, double seconds, bool final) {
  std::lock_guard<std::mutex> lock(print_mutex_);
  if (finished_) return;
  if (bar_) {
    // \r returns to the line start; the trailing spaces erase a longer previous line.
    err_ << "\r" << describe(done, seconds) << "    ";
    if (final) err_ << "\n";
  } else if (final) {
    err_ << label_ << ": " << done;
    if (total_ > 0) err_ << "/" << total_;
    err_ << " done in " << format_duration(seconds) << "\n";
  } else {
    err_ << describe(done, seconds) << "\n";
  }
  err_.flush();
  printed_ = true;
}

void Progress::finish() {
  {
    std::lock_guard<std::mutex> lock(print_mutex_);
    if (finished_ || !printed_ || quiet_) {
      finished_ = true;
      return;
    }
  }
  report(count(), elapsed_seconds(), true);
  std::lock_guard<std::mutex> lock(print_mutex_);
  finished_ = true;
}

}  // namespace delayspec::cli
