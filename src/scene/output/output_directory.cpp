#include "scene/output/output_directory.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

#include <nlohmann/json.hpp>

#include "scene/output/atomic_file.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/version.hpp"
#include "scene/output/metadata.hpp"

namespace delayspec::cli {

namespace fs = std::filesystem;

namespace {

fs::path normal_directory(const fs::path& dir) {
  fs::path normal = dir.lexically_normal();
  return normal.has_filename() ? normal : normal.parent_path();  // "out/x/" -> "out/x"
}

}  // namespace

OutputDirectory::OutputDirectory(fs::path dir) : dir_(normal_directory(dir)) {
  std::error_code ec;
  existed_ = fs::is_directory(dir_, ec);
  if (existed_) acquire();
}

OutputDirectory::~OutputDirectory() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // closing the last descriptor releases the flock
}

void OutputDirectory::acquire() {
  if (lock_fd_ >= 0) return;
  if (!existed_) {
    // This run found no DIR, so it must be the one to create it: a DIR that appeared meanwhile
    // belongs to another run (which may even have finished and released its lock already).
    std::error_code ec;
    if (dir_.has_parent_path()) {
      // The outermost missing parent, so that abandon() can remove the parents it made too.
      for (fs::path p = dir_.parent_path(); !p.empty() && !fs::exists(fs::symlink_status(p, ec)); p = p.parent_path())
        created_parent_ = p;
      fs::create_directories(dir_.parent_path(), ec);
    }
    const bool created = !ec && fs::create_directory(dir_, ec);
    if (ec) throw BadInput("cannot write `" + dir_.string() + "`: cannot create the directory: " + ec.message());
    if (!created)
      throw BadInput("`--out " + dir_.string() +
                     "`: another delayspec run created this directory after this one started; choose another "
                     "directory");
    existed_ = true;
    created_ = true;
  }
  const fs::path lock_path = dir_ / lock_name;
  // Never through a symbolic link (as the cache's lock): a link planted in a shared directory
  // would make this run create or lock a file elsewhere (issue 61 item 5). ELOOP: it is a link.
  const int fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0 && errno == ELOOP)
    throw BadInput("`" + lock_path.string() + "` is a symbolic link: delayspec does not lock through links; remove it");
  if (fd < 0) throw BadInput("cannot write `" + lock_path.string() + "`: " + std::strerror(errno));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    ::close(fd);
    if (error == EWOULDBLOCK)
      throw BadInput("`--out " + dir_.string() + "`: another delayspec run holds this directory (lock `" +
                     lock_path.string() + "`); wait for it to finish, or choose another directory");
    throw BadInput("cannot lock `" + lock_path.string() + "`: " + std::strerror(error));
  }
  lock_fd_ = fd;
}

void OutputDirectory::note_write(const fs::path& target) {
  const fs::path relative = target.lexically_normal().lexically_relative(dir_);
  if (relative.empty() || *relative.begin() == "..") return;  // not in DIR
  std::lock_guard<std::mutex> guard(mutex_);
  acquire();
  if (relative == marker_name) return;  // finish() itself
  const std::string entry = relative.begin()->string();
  if (!entries_.count(entry)) {
    std::error_code ec;
    entries_[entry] = !fs::exists(fs::symlink_status(dir_ / entry, ec));
  }
  if (!marker_removed_) {
    // Before the first new byte lands in DIR, the directory stops claiming to be complete.
    const fs::path marker = dir_ / marker_name;
    if (::unlink(marker.c_str()) != 0 && errno != ENOENT)
      throw BadInput("cannot write `" + marker.string() + "`: cannot remove the previous one: " + std::strerror(errno));
    marker_removed_ = true;
  }
  if (relative.has_parent_path()) return;  // working files in subdirectories (sweep's points/) are not listed
  files_.insert(relative.string());
}

void OutputDirectory::finish(const std::string& command, int exit_status) {
  if (exit_status != 0 && exit_status != 3) return;
  std::set<std::string> files;
  {
    std::lock_guard<std::mutex> guard(mutex_);
    files = files_;
  }
  const nlohmann::json marker = {{"command", command},
                                 {"exit_status", exit_status},
                                 {"files", files},
                                 {"delayspec_version", DELAYSPEC_VERSION},
                                 {"finished_utc", utc_now_iso8601()}};
  write(dir_ / marker_name, marker.dump(2) + "\n");  // takes the lock if nothing else did
}

void OutputDirectory::abandon() noexcept {
  std::lock_guard<std::mutex> guard(mutex_);
  if (lock_fd_ < 0) return;  // nothing written: nothing created
  std::error_code ec;
  if (created_) {
    // The whole directory is this run's (the lock kept every other run out of it).
    fs::remove_all(dir_, ec);
    // Parents it created, only while empty: another run may have chosen a directory beside DIR.
    for (fs::path p = dir_.parent_path(); !created_parent_.empty() && p.has_relative_path(); p = p.parent_path()) {
      if (!fs::remove(p, ec)) break;  // not empty (or gone): stop
      if (p == created_parent_) break;
    }
    return;
  }
  for (const auto& [name, is_new] : entries_)
    if (is_new) fs::remove_all(dir_ / name, ec);
}

void OutputDirectory::write(const fs::path& target, const std::string& contents) {
  note_write(target);
  write_file_atomically(target, contents);
}

void write_output(const Invocation& inv, const fs::path& target, const std::string& contents) {
  if (inv.output) inv.output->write(target, contents);
  else write_file_atomically(target, contents);
}

void OutputFile::commit() {
  if (committed_) return;
  write_output(inv_, target_, buffer_.str());
  committed_ = true;
}

}  // namespace delayspec::cli
