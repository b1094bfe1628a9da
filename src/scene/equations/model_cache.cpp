#include "scene/equations/model_cache.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "delayspec/errors.hpp"
#include "scene/output/atomic_file.hpp"

namespace delayspec::cli {

UniqueFd& UniqueFd::operator=(UniqueFd&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.release();
  }
  return *this;
}

UniqueFd::~UniqueFd() {
  if (fd_ >= 0) ::close(fd_);
}

namespace {

std::string reason() { return std::strerror(errno); }

// The one rule for everything in the cache: this user's, and nobody else may write it.
bool private_to_user(const struct stat& st) {
  return st.st_uid == ::geteuid() && (st.st_mode & (S_IWGRP | S_IWOTH)) == 0;
}

std::string owner_and_mode(const struct stat& st) {
  char mode[8];
  std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
  return "owner uid " + std::to_string(st.st_uid) + ", mode " + mode + "; this is uid " + std::to_string(::geteuid());
}


// An entry just opened (`fd`, or -1 with errno set) must be a regular file of this user's that
// nobody else can write; BadInput naming it otherwise.
void require_private_file(const UniqueFd& fd, const std::filesystem::path& path, const std::string& action) {
  if (!fd)
    throw BadInput("`model_cache`: cannot " + action + " " + path.string() + " (" +
                   (errno == ELOOP ? std::string("a symbolic link, which the cache never follows") : reason()) +
                   "): delete it");
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0 || !S_ISREG(st.st_mode) || !private_to_user(st))
    throw BadInput("`model_cache`: " + path.string() + " is not a regular file that is yours and writable by you alone (" +
                   owner_and_mode(st) + "): delete it");
}

}  // namespace

ModelCacheDir::ModelCacheDir(const std::filesystem::path& dir) : path_(dir) {
  const std::string key = "`model_cache = " + dir.string() + "`: ";
  if (dir.empty()) throw BadInput("`model_cache` is empty: name a directory");
  if (::mkdir(dir.c_str(), 0700) != 0 && errno == ENOENT) {
    std::error_code ec;
    std::filesystem::create_directories(dir.parent_path(), ec);
    ::mkdir(dir.c_str(), 0700);
  }
  dir_ = UniqueFd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (!dir_) throw BadInput(key + "cannot create or open the directory (" + reason() + ")");
  struct stat st {};
  if (::fstat(dir_.get(), &st) != 0) throw BadInput(key + "cannot read the directory (" + reason() + ")");
  if (!private_to_user(st))
    throw BadInput(key + "the directory holds compiled models that delayspec runs, so it must be yours and writable by " +
                   "you alone (" + owner_and_mode(st) + "): " +
                   (st.st_uid == ::geteuid() ? "`chmod go-w " + dir.string() + "` if only you ever wrote there, or " : "") +
                   "choose another with --set model_cache=DIR");
}

UniqueFd ModelCacheDir::open_entry(const std::string& name) const {
  UniqueFd fd(::openat(dir_.get(), name.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK));
  if (!fd && errno == ENOENT) return fd;
  require_private_file(fd, entry_path(name), "open");
  return fd;
}

std::optional<std::string> ModelCacheDir::read_entry(const std::string& name) const {
  const UniqueFd fd = open_entry(name);
  if (!fd) return std::nullopt;
  std::string text;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t got = ::read(fd.get(), buffer, sizeof buffer);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) throw BadInput("`model_cache`: cannot read " + entry_path(name).string() + " (" + reason() + ")");
    if (got == 0) return text;
    text.append(buffer, static_cast<size_t>(got));
  }
}

UniqueFd ModelCacheDir::create_entry(const std::string& name) const {
  UniqueFd fd(::openat(dir_.get(), name.c_str(), O_WRONLY | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0600));
  if (!fd) throw BadInput("`model_cache`: cannot write " + entry_path(name).string() + " (" + reason() + ")");
  // An entry that exists already (the compiler's source or log) must be the user's too, as every
  // entry read is: another user's world-writable file would be written and then compiled
  // (issue 61 item 4). Checked before it is truncated.
  require_private_file(fd, entry_path(name), "write");
  if (::ftruncate(fd.get(), 0) != 0)
    throw BadInput("`model_cache`: cannot write " + entry_path(name).string() + " (" + reason() + ")");
  return fd;
}

void ModelCacheDir::write_entry(const std::string& name, const std::string& text) const {
  // Not flushed to disk (as the cache's writes never were): an entry lost in a machine crash is
  // missing or fails its checksum when loaded (equation_plugin.cpp) and is compiled again.
  try {
    write_atomically_at(dir_.get(), name, text, 0600, Flush::skip);
  } catch (const AtomicWriteFailed& e) {
    throw BadInput("`model_cache`: cannot write " + entry_path(name).string() + " (" + e.step + ": " +
                   std::strerror(e.error) + ")");
  }
}

void ModelCacheDir::make_private(const std::string& name) const {
  const UniqueFd fd(::openat(dir_.get(), name.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK));
  struct stat st {};
  if (fd && ::fstat(fd.get(), &st) == 0 && S_ISREG(st.st_mode) && st.st_uid == ::geteuid())
    ::fchmod(fd.get(), st.st_mode & 0700);
}

void ModelCacheDir::rename_entry(const std::string& from, const std::string& to) const {
  // renameat replaces a link named `to` itself, it does not follow it.
  if (::renameat(dir_.get(), from.c_str(), dir_.get(), to.c_str()) != 0)
    throw BadInput("`model_cache`: cannot rename " + entry_path(from).string() + " to " + to + " (" + reason() + ")");
}

void ModelCacheDir::remove_entry(const std::string& name) const { ::unlinkat(dir_.get(), name.c_str(), 0); }

std::vector<std::string> ModelCacheDir::entries_starting_with(const std::string& prefix) const {
  std::vector<std::string> names;
  const int fd = ::openat(dir_.get(), ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return names;
  DIR* d = ::fdopendir(fd);
  if (!d) {
    ::close(fd);
    return names;
  }
  while (const dirent* e = ::readdir(d)) {
    const std::string n = e->d_name;
    if (n.compare(0, prefix.size(), prefix) == 0) names.push_back(n);
  }
  ::closedir(d);
  return names;
}

UniqueFd ModelCacheDir::lock(const std::string& name) const {
  UniqueFd fd(::openat(dir_.get(), name.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0600));
  if (!fd && (errno == EROFS || errno == EACCES || errno == EPERM)) return fd;  // EPERM: an immutable directory
  require_private_file(fd, entry_path(name), "create the lock file");
  while (::flock(fd.get(), LOCK_EX) != 0)
    if (errno != EINTR) throw BadInput("`model_cache`: cannot lock " + entry_path(name).string() + " (" + reason() + ")");
  return fd;
}

std::filesystem::path default_model_cache() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg == '/')
    return std::filesystem::path(xdg) / "delayspec";
  if (const char* home = std::getenv("HOME"); home && *home) return std::filesystem::path(home) / ".cache" / "delayspec";
  std::error_code ec;
  std::filesystem::path tmp = std::filesystem::temp_directory_path(ec);
  if (ec) tmp = "/tmp";
  return tmp / ("delayspec-cache-" + std::to_string(::geteuid()));
}

}  // namespace delayspec::cli
