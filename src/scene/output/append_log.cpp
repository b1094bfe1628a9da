#include "scene/output/append_log.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

#include "delayspec/errors.hpp"
#include "scene/output/atomic_file.hpp"

namespace delayspec::cli {

namespace {

[[noreturn]] void cannot_append(const std::filesystem::path& path, const std::string& what, int error) {
  throw BadInput("cannot write `" + path.string() + "`: " + what + std::strerror(error));
}

}  // namespace

AppendLog::AppendLog(std::filesystem::path path) : path_(std::move(path)) {
  const std::filesystem::path parent = path_.parent_path().empty() ? "." : path_.parent_path();
  std::error_code ec;
  std::filesystem::create_directories(parent, ec);
  if (ec) cannot_append(path_, "cannot create directory `" + parent.string() + "`: ", ec.value());
  fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_APPEND | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd_ < 0) cannot_append(path_, "", errno);
  // A line cut short by a killed run: end it, so that the next record is a line of its own.
  struct stat st {};
  char last = '\n';
  if (::fstat(fd_, &st) == 0 && st.st_size > 0 && ::pread(fd_, &last, 1, st.st_size - 1) == 1 && last != '\n') {
    if (const int error = write_whole(fd_, "\n"); error != 0) {
      ::close(fd_);
      cannot_append(path_, "write failed: ", error);
    }
  }
}

AppendLog::~AppendLog() {
  if (fd_ >= 0) ::close(fd_);
}

void AppendLog::append(const std::string& line) {
  const std::string text = line + "\n";
  std::lock_guard<std::mutex> guard(mutex_);
  if (const int error = write_whole(fd_, text); error != 0) cannot_append(path_, "write failed: ", error);
}

}  // namespace delayspec::cli
