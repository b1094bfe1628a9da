#pragma once
// The command table of the `delayspec` program and the invocation every command receives.
// A command reads its keys from the Config, calls config.check_all_used() before any heavy
// work (so a typo fails fast, exit 2), computes, and writes one result: text on `out`, or with
// --json exactly one JSON object on `out`. Progress and warnings go to `err`.
// Exceptions: BadInput -> exit 2, NumericalFailure -> exit 3 (handled in run_cli).
#include <map>
#include <optional>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "scene/keys/config.hpp"
#include "scene/output/invocation.hpp"

namespace delayspec::cli {

using CommandFunction = int (*)(Config&, const Invocation&);

int command_floquet(Config& config, const Invocation& inv);
int command_lyapunov(Config& config, const Invocation& inv);
int command_sweep(Config& config, const Invocation& inv);
int command_converge(Config& config, const Invocation& inv);
int command_bench(Config& config, const Invocation& inv);
int command_run(Config& config, const Invocation& inv);
int command_chart(Config& config, const Invocation& inv);
int command_basin(Config& config, const Invocation& inv);
int command_plot(Config& config, const Invocation& inv);
int command_simulate(Config& config, const Invocation& inv);
int command_continue(Config& config, const Invocation& inv);

// `run`'s check of a scene before anything computes: the analyses it lists (without `analyses`,
// the one command that reads all its keys), each run in key-collection mode; every key of the
// scene must be read by one of them. BadInput naming the first problem.
struct RunPlan {
  std::vector<std::string> analyses;
  std::set<std::string> known_keys;  // read by at least one analysis (or scene-level)
};
RunPlan plan_run(Config& config);

// The command table (name -> function); `run` dispatches a scene's analyses through it.
const std::map<std::string, CommandFunction>& command_table();
// What a command does, in one sentence that starts with its usage ("delayspec plot DIR: ..."):
// the first line of `delayspec COMMAND --help`. Empty for an unknown command.
const std::string& command_summary(const std::string& command);

// BadInput "unknown command `NAME` (commands: ...)" unless `command` is in the table: the one
// check of a command's name, for the program, `keys_help` and the Python module alike.
void require_known_command(const std::string& command);

// What a command does with `--out DIR`: nothing, writes its files there (run_cli then holds the
// directory's lock, output_directory.hpp), or reads results from there (plot); and whether it
// continues an interrupted run with `--resume`. run_cli refuses a flag the command ignores.
enum class OutDirUse { ignored, written, read };
struct OutputUse {
  OutDirUse out = OutDirUse::ignored;
  bool resume = false;
};
OutputUse output_use(const std::string& command);

// Bad input in `--out DIR` / `--resume` for `command` (BadInput naming the flag and the command):
// `out_given` whether an output directory was given at all, `out_dir` its name.
void check_output_flags(const std::string& command, bool out_given, const std::string& out_dir, bool resume);

// Runs `inv.command` on `config` (scene and overrides already applied), as the program does
// after parsing its arguments: marks the scene-level keys, and holds the output directory's lock
// while a command writes there. Returns the command's exit status (0, or 3 for failures recorded
// in a complete result); throws BadInput and NumericalFailure. The one entry of the CLI and the
// Python module.
int run_command(Config& config, const Invocation& inv);

// Runs the program: parses argv, dispatches, maps errors to exit codes. Never throws.
int run_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace delayspec::cli
