#pragma once
// The directory of compiled equation models (equation_plugin.hpp). It holds native code that this
// process loads and runs, so it must be private to the user: a scene is untrusted input (people
// download scenes), and whoever can write into the cache can make delayspec run their code.
// Hence, in this one place:
// - the directory comes from the command line (`--set model_cache=DIR`, a Python keyword), the
//   environment ($XDG_CACHE_HOME, $HOME) or a per-user fallback, never from a scene file
//   (equation_model.cpp refuses `model_cache` there);
// - it is refused (BadInput naming `model_cache`) unless this user owns it and neither group nor
//   others can write it; a missing one is created with mode 0700;
// - its entries are opened relative to the directory's descriptor, never through a symbolic link
//   (O_NOFOLLOW), and only when they are regular files this user owns that others cannot write;
//   new files are created exclusively (O_EXCL) and renamed into place.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace delayspec::cli {

// A file descriptor closed at the end of its scope (-1: none).
class UniqueFd {
 public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  UniqueFd(UniqueFd&& other) noexcept : fd_(other.release()) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept;
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  ~UniqueFd();
  int get() const { return fd_; }
  explicit operator bool() const { return fd_ >= 0; }
  int release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }

 private:
  int fd_ = -1;
};

class ModelCacheDir {
 public:
  // Opens `dir`, creating it (0700, missing parents as the umask says) when it does not exist.
  // BadInput naming `model_cache` and the reason when it cannot be created or is not a private
  // directory of this user.
  explicit ModelCacheDir(const std::filesystem::path& dir);

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path entry_path(const std::string& name) const { return path_ / name; }

  // Opens the entry for reading: an empty UniqueFd when it does not exist; BadInput when it is a
  // symbolic link, not a regular file, not this user's, or writable by group or others.
  UniqueFd open_entry(const std::string& name) const;
  // The entry's whole contents, or nothing when it does not exist (checked as open_entry).
  std::optional<std::string> read_entry(const std::string& name) const;
  // Writes the entry through a new temporary file (created with O_EXCL, mode 0600) renamed onto it.
  void write_entry(const std::string& name, const std::string& text) const;
  // Creates or truncates the entry for writing (mode 0600, never through a link).
  UniqueFd create_entry(const std::string& name) const;
  // Clears the group and other bits of an entry this user owns (what a compiler made under the
  // umask, 0775 under 002); nothing when it does not exist or is a link.
  void make_private(const std::string& name) const;
  void rename_entry(const std::string& from, const std::string& to) const;
  void remove_entry(const std::string& name) const;  // no error when it does not exist
  // The names of the entries that start with `prefix`.
  std::vector<std::string> entries_starting_with(const std::string& prefix) const;

  // An exclusive flock on the entry `name` (created 0600, never through a link), held until the
  // returned descriptor closes. Empty when the directory is read-only for this process (EROFS,
  // EACCES, EPERM): a read-only cache can still serve the models it holds.
  UniqueFd lock(const std::string& name) const;

 private:
  std::filesystem::path path_;
  UniqueFd dir_;
};

// $XDG_CACHE_HOME/delayspec (absolute XDG_CACHE_HOME only), else $HOME/.cache/delayspec, else
// $TMPDIR/delayspec-cache-UID: a per-user folder, so that no user ever shares another's.
std::filesystem::path default_model_cache();

}  // namespace delayspec::cli
