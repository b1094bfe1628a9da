#include "scene/output/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <system_error>

#include "delayspec/errors.hpp"

namespace delayspec::cli {

namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what, int error) {
  throw BadInput("cannot write `" + path.string() + "`: " + what + ": " + std::strerror(error));
}

std::string temporary_name(const std::string& name) {
  static std::atomic<unsigned long> sequence{0};
  std::string temp(".");  // (append, not operator+: GCC 12 warns falsely on "." + string)
  temp.append(name).append(".tmp-").append(std::to_string(::getpid()));
  temp.append("-").append(std::to_string(sequence.fetch_add(1)));
  return temp;
}

}  // namespace

int write_whole(int fd, const std::string& text) {
  size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return errno;
    written += static_cast<size_t>(n);
  }
  return 0;
}

void write_atomically_at(int dir_fd, const std::string& name, const std::string& contents, unsigned mode,
                         Flush flush) {
  const std::string temp = temporary_name(name);
  const int fd = ::openat(dir_fd, temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC,
                          static_cast<mode_t>(mode));
  if (fd < 0) throw AtomicWriteFailed{"cannot create `" + temp + "`", errno};
  if (const int error = write_whole(fd, contents); error != 0) {
    ::close(fd);
    ::unlinkat(dir_fd, temp.c_str(), 0);
    throw AtomicWriteFailed{"write failed", error};
  }
  // fsync before rename: after a crash the new name never points at unwritten blocks (Flush).
  int error = flush == Flush::skip || ::fsync(fd) == 0 ? 0 : errno;
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error != 0) {
    ::unlinkat(dir_fd, temp.c_str(), 0);
    throw AtomicWriteFailed{"flush failed", error};
  }
  if (::renameat(dir_fd, temp.c_str(), dir_fd, name.c_str()) != 0) {
    error = errno;
    ::unlinkat(dir_fd, temp.c_str(), 0);
    throw AtomicWriteFailed{"rename failed", error};
  }
}

void write_file_atomically(const std::filesystem::path& target, const std::string& contents) {
  if (target.filename().empty()) throw BadInput("cannot write `" + target.string() + "`: not a file name");
  const std::filesystem::path parent = target.parent_path().empty() ? "." : target.parent_path();
  std::error_code ec;
  std::filesystem::create_directories(parent, ec);
  if (ec) fail(target, "cannot create directory `" + parent.string() + "`", ec.value());
  const int dir_fd = ::open(parent.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd < 0) fail(target, "cannot open directory `" + parent.string() + "`", errno);
  try {
    write_atomically_at(dir_fd, target.filename().string(), contents, 0644, Flush::to_disk);
  } catch (const AtomicWriteFailed& e) {
    ::close(dir_fd);
    fail(target, e.step, e.error);
  }
  ::close(dir_fd);
}

void AtomicFile::commit() {
  if (committed_) return;
  write_file_atomically(target_, buffer_.str());
  committed_ = true;
}

}  // namespace delayspec::cli
