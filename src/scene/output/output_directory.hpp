#pragma once
// One run per output directory, and a marker that says when the run's files are complete.
// run_cli opens an OutputDirectory for every command that writes into `--out DIR` and keeps it
// for the whole command; the commands themselves know nothing of it (their writes go through
// write_file_atomically, which reports each one here).
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
// Example (run_cli):
//     OutputDirectory out(dir);                 // BadInput if another run holds DIR
//     const int status = command(config, inv);  // writes DIR/... through write_file_atomically
//     out.finish("sweep", status);              // DIR/complete.json
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <string>

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

  // After bad input: removes what this run created (see above). Never throws (it runs while a
  // BadInput propagates); what cannot be removed stays, and DIR still has no complete.json.
  void abandon() noexcept;

  static constexpr const char* lock_name = ".delayspec-lock";
  static constexpr const char* marker_name = "complete.json";

 private:
  friend void before_output_write(const std::filesystem::path& target);
  void acquire();  // creates DIR if needed and takes the lock (BadInput if held); idempotent
  void note_write(const std::filesystem::path& target);

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
  OutputDirectory* previous_ = nullptr;
};

// Called by write_file_atomically before it writes `target`: when target lies in the open
// OutputDirectory, takes the lock if not yet held, removes complete.json on the first write and
// records the file. Does nothing when no OutputDirectory is open (e.g. the library's tests).
void before_output_write(const std::filesystem::path& target);

}  // namespace delayspec::cli
