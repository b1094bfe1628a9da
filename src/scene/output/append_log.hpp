#pragma once
// A file that grows by whole lines, written by many threads of one process: the point log of a
// sweep, chart or basin (point_files.hpp). Each line goes to the kernel in one write(2) on a
// descriptor opened with O_APPEND, so lines from different threads never interleave, and a
// process killed mid-run leaves every line it finished whole; at worst the last line is cut short
// (a reader skips a line it cannot parse). Opening a log whose last line was cut starts a new line
// first, so the cut line never swallows the next record.
//
// Opened read-write (to look at the last byte) without following a link (O_NOFOLLOW), created
// 0644. Not flushed to disk (no fsync): a line lost in a machine crash is a point that --resume
// computes again, and an fsync per point would double a chart point's cost (atomic_file.hpp).
// Errors throw BadInput "cannot write `PATH`: REASON" (directory not creatable, disk full,
// permission): the user asked for an output location that cannot be written.
//
// Example (point_files.cpp):
//     AppendLog log(dir / "points" / "rank_00000.jsonl");
//     log.append(record.dump());   // the line, without its newline
#include <filesystem>
#include <mutex>
#include <string>

namespace delayspec::cli {

class AppendLog {
 public:
  // Creates the parent directory if needed and opens (or creates) the log.
  explicit AppendLog(std::filesystem::path path);
  ~AppendLog();
  AppendLog(const AppendLog&) = delete;
  AppendLog& operator=(const AppendLog&) = delete;

  // Appends `line` and a newline, in one write. Thread-safe.
  void append(const std::string& line);

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  std::mutex mutex_;  // one write at a time: a partial write must finish before the next line
};

}  // namespace delayspec::cli
