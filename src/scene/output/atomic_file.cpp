#include "scene/output/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <system_error>

#include "delayspec/errors.hpp"
#include "scene/output/output_directory.hpp"

namespace delayspec::cli {

namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what, int error) {
  throw BadInput("cannot write `" + path.string() + "`: " + what + ": " + std::strerror(error));
}

std::filesystem::path temporary_name(const std::filesystem::path& target) {
  static std::atomic<unsigned long> sequence{0};
  std::string name(".");  // (append, not operator+: GCC 12 warns falsely on "." + string)
  name.append(target.filename().string()).append(".tmp-").append(std::to_string(::getpid()));
  name.append("-").append(std::to_string(sequence.fetch_add(1)));
  return target.parent_path() / name;
}

}  // namespace

void write_file_atomically(const std::filesystem::path& target, const std::string& contents, Flush flush) {
  if (target.filename().empty()) throw BadInput("cannot write `" + target.string() + "`: not a file name");
  before_output_write(target);  // the lock and the completeness marker of --out DIR
  const std::filesystem::path parent = target.parent_path().empty() ? "." : target.parent_path();
  std::error_code ec;
  std::filesystem::create_directories(parent, ec);
  if (ec) fail(target, "cannot create directory `" + parent.string() + "`", ec.value());

  const std::filesystem::path temp = temporary_name(parent / target.filename());
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) fail(target, "cannot create `" + temp.string() + "`", errno);
  size_t written = 0;
  while (written < contents.size()) {
    const ssize_t n = ::write(fd, contents.data() + written, contents.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int error = errno;
      ::close(fd);
      ::unlink(temp.c_str());
      fail(target, "write failed", error);
    }
    written += static_cast<size_t>(n);
  }
  // fsync before rename: after a crash the new name never points at unwritten blocks (Flush).
  int error = flush == Flush::skip || ::fsync(fd) == 0 ? 0 : errno;
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error != 0) {
    ::unlink(temp.c_str());
    fail(target, "flush failed", error);
  }
  if (std::rename(temp.c_str(), target.c_str()) != 0) {
    error = errno;
    ::unlink(temp.c_str());
    fail(target, "rename failed", error);
  }
}

void AtomicFile::commit() {
  if (committed_) return;
  write_file_atomically(target_, buffer_.str());
  committed_ = true;
}

}  // namespace delayspec::cli
