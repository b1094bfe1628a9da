#include "scene/equations/child_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <mutex>

extern char** environ;

namespace delayspec::cli {

namespace {

// The signals that end delayspec by default and that a user sends to stop it.
constexpr std::array<int, 4> kStopSignals = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};

// The process groups of the children running now (0: a free slot), read by the handler.
constexpr int kMaxChildren = 16;
std::array<std::atomic<pid_t>, kMaxChildren> running_groups{};

// The dispositions before the first child started, restored when the last one ends (or by the
// handler before it re-raises). Guarded by `handlers_mutex` outside the handler.
std::mutex handlers_mutex;
int children_running = 0;
std::array<struct sigaction, kStopSignals.size()> previous{};

// Async-signal-safe: kill, sigaction and raise only.
void kill_children_and_reraise(int sig) {
  for (auto& group : running_groups)
    if (const pid_t g = group.load(); g > 0) ::kill(-g, SIGKILL);
  for (size_t k = 0; k < kStopSignals.size(); ++k)
    if (kStopSignals[k] == sig) ::sigaction(sig, &previous[k], nullptr);
  ::raise(sig);
}

void install_handlers() {
  const std::lock_guard<std::mutex> lock(handlers_mutex);
  if (children_running++ > 0) return;
  struct sigaction action {};
  action.sa_handler = kill_children_and_reraise;
  sigemptyset(&action.sa_mask);
  for (size_t k = 0; k < kStopSignals.size(); ++k) {
    ::sigaction(kStopSignals[k], nullptr, &previous[k]);
    // An ignored signal (SIGHUP under nohup) stays ignored: it must not stop the compile either.
    if (previous[k].sa_handler != SIG_IGN) ::sigaction(kStopSignals[k], &action, nullptr);
  }
}

void restore_handlers() {
  const std::lock_guard<std::mutex> lock(handlers_mutex);
  if (--children_running > 0) return;
  for (size_t k = 0; k < kStopSignals.size(); ++k) {
    // A handler that already ran has put the previous one back; do not undo what it chose.
    struct sigaction now {};
    ::sigaction(kStopSignals[k], nullptr, &now);
    if (now.sa_handler == kill_children_and_reraise) ::sigaction(kStopSignals[k], &previous[k], nullptr);
  }
}

std::atomic<pid_t>* register_group(pid_t group) {
  for (auto& slot : running_groups) {
    pid_t free = 0;
    if (slot.compare_exchange_strong(free, group)) return &slot;
  }
  return nullptr;
}

// The child's life after fork, never returning; async-signal-safe calls only (the parent may have
// other threads). It starts the program as its own child, in its group, and waits for whichever
// comes first: the program's end (its exit status, or its signal, passed on as this process's) or
// the end of `alive`, the pipe whose write end only delayspec holds: delayspec is gone, however it
// died (SIGKILL included, which it cannot catch), and the whole group goes with it (cc1plus, as
// and ld are the driver's children: PR_SET_PDEATHSIG on the driver alone left them running).
[[noreturn]] void supervise(char* const* args, int alive) {
  const pid_t program = ::fork();
  if (program < 0) ::_exit(127);
  if (program == 0) {
    ::execve(args[0], args, environ);
    ::_exit(127);
  }
  for (;;) {
    int status = 0;
    if (::waitpid(program, &status, WNOHANG) == program) {
      if (WIFEXITED(status)) ::_exit(WEXITSTATUS(status));
      struct sigaction defaults {};
      defaults.sa_handler = SIG_DFL;
      ::sigaction(WTERMSIG(status), &defaults, nullptr);
      ::kill(::getpid(), WTERMSIG(status));
      ::_exit(128 + WTERMSIG(status));
    }
    pollfd end{alive, POLLIN, 0};
    if (::poll(&end, 1, 10) > 0) ::kill(0, SIGKILL);  // EOF (or an error): delayspec is gone
  }
}

}  // namespace

ChildOutcome run_child(const std::vector<std::string>& argv, int output_fd, double time_limit_seconds) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t parent = ::getpid();
  // alive: read by the child's supervisor, written by nobody; it ends when this process does.
  int alive[2];
  if (::pipe2(alive, O_CLOEXEC) != 0) return {};
  install_handlers();
  // Between fork and exec the child calls async-signal-safe functions only (this process may
  // have other threads).
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::setpgid(0, 0);
    ::close(alive[1]);
    if (::getppid() != parent) ::_exit(127);  // the parent died before the child could watch it
    // Our handler is not the child's (exec resets it anyway; this closes the window before exec);
    // an ignored signal stays ignored, as exec keeps it.
    struct sigaction defaults {};
    defaults.sa_handler = SIG_DFL;
    for (size_t k = 0; k < kStopSignals.size(); ++k)
      if (previous[k].sa_handler != SIG_IGN) ::sigaction(kStopSignals[k], &defaults, nullptr);
    const int watch = ::fcntl(alive[0], F_DUPFD_CLOEXEC, 3);  // above 0..2, whichever of them was closed
    if (watch < 0) ::_exit(127);
    ::dup2(output_fd, STDOUT_FILENO);
    ::dup2(output_fd, STDERR_FILENO);
    // Only `alive` stays open beyond them (as descriptor 3): a write end of another child's pipe,
    // inherited from a fork of another thread, would keep that child's supervisor from its end.
    if (watch != 3) {
      ::dup2(watch, 3);
      ::fcntl(3, F_SETFD, FD_CLOEXEC);
    }
    ::close_range(4, ~0U, 0);
    supervise(args.data(), 3);
  }
  ::close(alive[0]);
  ChildOutcome outcome;
  if (pid < 0) {
    ::close(alive[1]);
    restore_handlers();
    return outcome;
  }
  ::setpgid(pid, pid);  // also from here, so the group exists before we may kill it
  std::atomic<pid_t>* slot = register_group(pid);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(time_limit_seconds);
  // Wait without reaping (WNOWAIT): while the driver is an unreaped zombie its pid, and so its
  // group's id, cannot be reused, so killing the group after it ended hits only what it left.
  for (;;) {
    siginfo_t info{};
    const int waited = ::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT);
    if (waited == 0 && info.si_pid == pid) break;
    if (waited < 0 && errno != EINTR) break;
    if (std::chrono::steady_clock::now() > deadline) {
      outcome.end = ChildOutcome::End::timed_out;
      break;
    }
    const timespec pause{0, 10'000'000};  // 10 ms: a compile takes seconds
    ::nanosleep(&pause, nullptr);
  }
  ::kill(-pid, SIGKILL);  // whatever is left of the group (all of it after a time-out)
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  ::close(alive[1]);
  if (slot) slot->store(0);
  restore_handlers();
  if (outcome.end == ChildOutcome::End::timed_out) return outcome;
  if (WIFEXITED(status)) {
    outcome.end = ChildOutcome::End::exited;
    outcome.code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    outcome.end = ChildOutcome::End::signalled;
    outcome.code = WTERMSIG(status);
  }
  return outcome;
}

}  // namespace delayspec::cli
