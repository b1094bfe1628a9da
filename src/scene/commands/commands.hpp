#pragma once
// The command table of the `delayspec` program and the invocation every command receives.
// A command reads its keys from the Config, calls config.check_all_used() before any heavy
// work (so a typo fails fast, exit 2), computes, and writes one result: text on `out`, or with
// --json exactly one JSON object on `out`. Progress and warnings go to `err`.
// Exceptions: BadInput -> exit 2, NumericalFailure -> exit 3 (handled by the front end: run_cli).
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

int command_equilibrium(Config& config, const Invocation& inv);
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
int command_boundary(Config& config, const Invocation& inv);

// `run`'s check of a scene before anything computes: the analyses it lists (without `analyses`,
// the one command that reads all its keys), each run in key-collection mode; every key of the
// scene must be read by one of them. BadInput naming the first problem.
struct RunPlan {
  std::vector<std::string> analyses;
  std::set<std::string> known_keys;  // read by at least one analysis (or scene-level)
};
RunPlan plan_run(Config& config);

// What a command does with `--out DIR`: nothing, writes its files there (run_command then holds
// the directory's lock, output_directory.hpp), or reads results from there (plot).
enum class OutDirUse { ignored, written, read };

// Everything the front ends know of one command: one row of the command table, read by the
// program (dispatch, --help, the --out and --resume checks), MPI (which commands the worker
// ranks run), the key registry (its probes) and the Python module (delayspec._delayspec.commands).
struct CommandSpec {
  std::string name;
  CommandFunction run = nullptr;
  // What it does, in one sentence that starts with its usage ("delayspec plot DIR: ..."): the
  // first line of `delayspec COMMAND --help`.
  std::string summary;
  OutDirUse out = OutDirUse::ignored;
  bool resume = false;       // continues an interrupted run in --out with --resume
  bool distributes = false;  // its points are spread over MPI ranks (the workers run it too)
  bool analysis = false;     // may be listed in a scene's `analyses` (not run, not plot)
  // Keys it requires (no default), with the placeholder the key registry's probe gives them so
  // that the command reaches its other reads; the swept key's placeholder is a name no model reads.
  std::map<std::string, std::string> placeholders;
};

// The command table, in name order; `run` dispatches a scene's analyses through it.
const std::vector<CommandSpec>& command_table();
bool is_command(const std::string& name);
// The row of `name`; BadInput "unknown command `NAME` (commands: ...)" when it is none: the one
// check of a command's name, for the program, `keys_help` and the Python module alike.
const CommandSpec& command_spec(const std::string& name);
// "basin, bench, ...": the names of the table.
std::string command_list();

// Bad input in `--out DIR` / `--resume` for `command` (BadInput naming the flag and the command):
// `out_given` whether an output directory was given at all, `out_dir` its name.
void check_output_flags(const std::string& command, bool out_given, const std::string& out_dir, bool resume);

// Runs `inv.command` on `config` (scene and overrides already applied), as the program does
// after parsing its arguments: marks the scene-level keys, and holds the output directory's lock
// while a command writes there. Returns the command's exit status (0, or 3 for failures recorded
// in a complete result); throws BadInput and NumericalFailure. The one entry of the CLI and the
// Python module.
int run_command(Config& config, const Invocation& inv);

}  // namespace delayspec::cli
