#pragma once
// A helper program run as a child that dies with delayspec: the compiler of an equation model
// (equation_plugin.cpp). The compiler driver starts cc1plus, as and ld as its own children, so
// killing the driver alone would leave them running; the child therefore gets a process group of
// its own, and that whole group is killed
// - when delayspec gets SIGINT, SIGTERM, SIGHUP or SIGQUIT while the child runs (the handler
//   kills the group, then re-raises the signal with the handler that was there before, so the
//   program still dies of it and Python still sees its KeyboardInterrupt);
// - when the time limit passes;
// - and when delayspec dies of anything else, SIGKILL included, which nothing can catch: the child
//   is a small supervisor that runs the program in the group and kills the group when the pipe
//   only delayspec writes to ends (child_process.cpp, supervise).
#include <string>
#include <vector>

namespace delayspec::cli {

struct ChildOutcome {
  enum class End { exited, signalled, timed_out, not_started } end = End::not_started;
  int code = 0;  // the exit status, or the signal
};

// Runs argv[0] (a path, no shell) with argv, its standard output and error into the open
// descriptor `output_fd`, and waits for it, at most `time_limit_seconds`.
ChildOutcome run_child(const std::vector<std::string>& argv, int output_fd, double time_limit_seconds);

}  // namespace delayspec::cli
