#pragma once
// One run per output directory, and a marker that says when the run's files are complete.
// run_command opens an OutputDirectory for every command that writes into `--out DIR`, keeps it
// for the whole command and hands it to the command in its Invocation (`inv.output`): the
// command's files go through write_output / OutputFile, which tell the directory before each write.
//
// Lock: `DIR/.delayspec-lock`, an flock(2) taken without waiting and held until the command
// returns (the kernel drops it when the process dies, so a killed run leaves no stale lock). It is
// taken when the run starts if DIR exists (before anything in DIR is read, e.g. by --resume),
// else by the first write, which creates DIR (a run stopped by bad input creates nothing). A run
// that finds the lock held, or finds that DIR was created by someone else after it started,
// stops with BadInput naming DIR.
//
// Bad input: a command that stops with BadInput after it wrote into DIR (a key found bad only
// when a point runs, a write past a file-size limit) leaves nothing of this run behind:
// abandon() removes DIR if this run created it, else every file and directory this run created
// directly in DIR (so a new run needs no --resume; the points of a resumed run, inside the
// existing points directory, stay for the next --resume).
//
// Completeness: `DIR/complete.json` is removed before the run's first write into DIR and written
// (atomically) after its last, when the command finished (exit 0, or 3 with its failures
// recorded in the files). It lists the files this run wrote directly in DIR. No complete.json:
// the directory holds an interrupted or failed run, or one still in progress.
//
// Example (run_command):
//     OutputDirectory out(dir);                 // BadInput if another run holds DIR
//     inv.output = &out;
//     const int status = command(config, inv);  // writes DIR/... through write_output(inv, ...)
//     out.finish("sweep", status);              // DIR/complete.json
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <string>

#include "scene/output/atomic_file.hpp"
#include "scene/output/invocation.hpp"

namespace delayspec::cli {

class OutputDirectory {
 public:
  // Takes the lock if `dir` is an existing directory; otherwise the first write will.
  explicit OutputDirectory(std::filesystem::path dir);
  ~OutputDirectory();
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;

  // Writes DIR/complete.json: {"command", "exit_status", "files", "delayspec_version", "finished_utc"}.
  void finish(const std::string& command, int exit_status);

  // Writes `target` atomically (write_file_atomically) after telling the directory: when target
  // lies in DIR, takes the lock if not yet held, removes complete.json on the first write and
  // records the file. Thread-safe.
  void write(const std::filesystem::path& target, const std::string& contents);

  // What write() tells the directory before it writes, for a file the caller writes itself (a
  // point log, point_files.hpp): call it before the file's first byte. Thread-safe.
  void note_write(const std::filesystem::path& target);

  // After bad input: removes what this run created (see above). Never throws (it runs while a
  // BadInput propagates); what cannot be removed stays, and DIR still has no complete.json.
  void abandon() noexcept;

  static constexpr const char* lock_name = ".delayspec-lock";
  static constexpr const char* marker_name = "complete.json";

 private:
  void acquire();  // creates DIR if needed and takes the lock (BadInput if held); idempotent

  std::filesystem::path dir_;
  bool existed_ = false;  // DIR existed when the run started (else the run must create it)
  bool created_ = false;  // this run created DIR
  std::filesystem::path created_parent_;  // the outermost parent of DIR this run created (or empty)
  int lock_fd_ = -1;
  bool marker_removed_ = false;
  std::set<std::string> files_;  // names written directly in DIR
  // Each name directly in DIR that this run wrote into (a file, or the directory of a file), and
  // whether it was new: decided at its first write, before any byte of this run lands there.
  std::map<std::string, bool> entries_;
  std::mutex mutex_;             // writes come from the worker threads of sweep
};

// A command's result file: through the run's OutputDirectory when it has one (inv.output), else
// (a command called without run_command) written atomically alone.
void write_output(const Invocation& inv, const std::filesystem::path& target, const std::string& contents);

// A result file built in memory and written by commit() through write_output. Output files of
// delayspec are small (tables, JSON): buffering them whole keeps the write a single step.
//     OutputFile csv(inv, dir / "chart.csv");
//     csv.stream() << header << rows;
//     csv.commit();             // without commit(), nothing is written
class OutputFile {
 public:
  OutputFile(const Invocation& inv, std::filesystem::path target) : inv_(inv), target_(std::move(target)) {}
  std::ostream& stream() { return buffer_; }
  const std::filesystem::path& path() const { return target_; }
  // Writes the file; a second commit() is a no-op.
  void commit();

 private:
  const Invocation& inv_;
  std::filesystem::path target_;
  std::ostringstream buffer_;
  bool committed_ = false;
};

}  // namespace delayspec::cli
