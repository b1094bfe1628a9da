#pragma once
// Atomic output files: every file a command writes goes through here. The contents are written
// to a hidden temporary file in the same directory (`.NAME.tmp-PID-SEQ`), flushed to disk, and
// renamed onto NAME (rename(2) within one file system is atomic). An interrupted run therefore
// leaves either the previous complete file or none, never a truncated file that looks
// complete; at worst a hidden `.NAME.tmp-*` file remains.
// Errors (directory missing and not creatable, disk full, permission) throw BadInput naming the
// path and the system's reason: the user asked for an output location that cannot be written.
// A pure function of its arguments: a command's results go through its OutputDirectory
// (output_directory.hpp: lock, completeness marker), which calls this; the model cache
// (model_cache.hpp) calls write_atomically_at in its own directory.
//
// Example:
//     AtomicFile file(out_dir / "exponents.csv");
//     file.stream() << "# delayspec 0.1.0\nk,lambda1\n";
//     file.commit();            // without commit(), the destructor discards the temporary
#include <filesystem>
#include <sstream>
#include <string>

namespace delayspec::cli {

// Whether the temporary is flushed to disk (fsync) before the rename. `skip` is for files whose
// reader survives their loss after a machine crash: the model cache's entries (model_cache.hpp),
// compiled again when one is missing or fails its checksum.
enum class Flush { to_disk, skip };

// The write itself, in the directory open as `dir_fd`: `name` gets `contents` through a temporary
// `.NAME.tmp-PID-SEQ` made with `mode` (O_EXCL | O_NOFOLLOW: never through a link), flushed as
// `flush` says, renamed onto `name` (renameat replaces a link named `name`, never follows it).
// On failure the temporary is removed and AtomicWriteFailed says which step and why.
struct AtomicWriteFailed {
  std::string step;       // "cannot create `TEMPORARY`", "write failed", "flush failed", "rename failed"
  int error = 0;          // errno
};
void write_atomically_at(int dir_fd, const std::string& name, const std::string& contents, unsigned mode,
                         Flush flush);

// Writes all of `text` to the descriptor (write(2) may take less than asked; EINTR is retried):
// 0, or the errno of the write that failed.
int write_whole(int fd, const std::string& text);

// Writes `contents` to `target` atomically (see above), mode 0644. Creates the parent directory if
// needed. BadInput "cannot write `target`: STEP: REASON".
void write_file_atomically(const std::filesystem::path& target, const std::string& contents);

// A file built in memory and written atomically by commit(). Output files of delayspec are
// small (tables, JSON), so buffering them whole is cheap and keeps the write a single step.
class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target) : target_(std::move(target)) {}
  std::ostream& stream() { return buffer_; }
  const std::filesystem::path& path() const { return target_; }
  // Writes and renames; a second commit() is a no-op.
  void commit();

 private:
  std::filesystem::path target_;
  std::ostringstream buffer_;
  bool committed_ = false;
};

}  // namespace delayspec::cli
