#include <algorithm>

#include "delayspec/errors.hpp"
#include "scene/commands/commands.hpp"
#include "scene/commands/key_registry.hpp"
#include "scene/output/output_directory.hpp"
#include "scene/points/ranks.hpp"

namespace delayspec::cli {

const std::vector<CommandSpec>& command_table() {
  // In name order (the order of listings and of the key registry's probes).
  static const std::vector<CommandSpec> table = {
      {.name = "basin",
       .run = command_basin,
       .summary = "delayspec basin [SCENE]: basins of attraction, the attractor (its period) reached from each constant initial "
                "history of a grid.",
       .out = OutDirUse::written,  // point logs: --resume computes only the missing points
       .resume = true,
       .distributes = true,
       .analysis = true,
       .placeholders = {}},
      {.name = "bench",
       .run = command_bench,
       .summary = "delayspec bench [SCENE]: speed against error, the Krylov and the dense eigensolvers side by side at several "
                "N.",
       .out = OutDirUse::written,
       .resume = false,
       .distributes = false,
       .analysis = true,
       .placeholders = {}},
      {.name = "boundary",
       .run = command_boundary,
       .summary = "delayspec boundary [SCENE]: a stability boundary (Neimark-Sacker, period-doubling or fold) followed as a "
                "curve in two parameters, each point extrapolated to N -> infinity with an error estimate.",
       .out = OutDirUse::written,
       .resume = false,
       .distributes = false,
       .analysis = true,
       .placeholders = {{"boundary_x", "(stepped)"},
                        {"boundary_y", "(solved)"},
                        {"boundary_x_from", "0"},
                        {"boundary_x_to", "1"},
                        {"boundary_y_from", "0"},
                        {"boundary_y_to", "1"}}},
      {.name = "chart",
       .run = command_chart,
       .summary = "delayspec chart [SCENE]: a stability chart, the spectral radius |mu_1| over a grid of two parameters.",
       .out = OutDirUse::written,  // point logs, as sweep
       .resume = true,
       .distributes = true,
       .analysis = true,
       .placeholders = {}},
      {.name = "continue",
       .run = command_continue,
       .summary = "delayspec continue [SCENE]: the periodic orbit continued in one parameter, its bifurcations located and "
                "extrapolated to N -> infinity (continue_object = equilibrium: the equilibria, their folds and Hopf points).",
       .out = OutDirUse::written,
       .resume = false,
       .distributes = false,
       .analysis = true,
       .placeholders = {{"continue_key", "(continued)"}, {"continue_from", "0"}, {"continue_to", "1"}}},
      {.name = "converge",
       .run = command_converge,
       .summary = "delayspec converge [SCENE]: the leading multipliers at several N: their errors, the observed order and the "
                "Richardson extrapolation to N -> infinity.",
       .out = OutDirUse::written,
       .resume = false,
       .distributes = false,
       .analysis = true,
       .placeholders = {}},
      {.name = "equilibrium",
       .run = command_equilibrium,
       .summary = "delayspec equilibrium [SCENE]: an equilibrium of an autonomous model and its rightmost characteristic "
                "roots, exact (refined on the characteristic function), with their stability.",
       .out = OutDirUse::ignored,
       .resume = false,
       .distributes = false,
       .analysis = true,
       .placeholders = {}},
      {.name = "floquet",
       .run = command_floquet,
       .summary = "delayspec floquet [SCENE]: the leading Floquet multipliers of the periodic orbit, each with its distance to "
                "the N -> infinity value, and a verdict: stable, unstable or undecided.",
       .out = OutDirUse::ignored,  // results on stdout only
       .resume = false,
       .distributes = false,
       .analysis = true,
       .placeholders = {}},
      {.name = "lyapunov",
       .run = command_lyapunov,
       .summary = "delayspec lyapunov [SCENE]: the leading Lyapunov exponents of a trajectory from the constant initial "
                "history, with their statistical errors.",
       .out = OutDirUse::ignored,
       .resume = false,
       .distributes = false,
       .analysis = true,
       .placeholders = {}},
      {.name = "plot",
       .run = command_plot,
       .summary = "delayspec plot DIR: figures (PNG, SVG and their gnuplot scripts) of the results a command wrote in DIR, into "
                "DIR/plots/.",
       .out = OutDirUse::read,  // `plot --out DIR` = `plot DIR`
       .resume = false,
       .distributes = false,
       .analysis = false,
       .placeholders = {}},
      {.name = "run",
       .run = command_run,
       .summary = "delayspec run SCENE --out DIR: the analyses the scene lists, each result kept as a file in DIR.",
       .out = OutDirUse::written,  // passes --resume to its analyses (command_run.cpp)
       .resume = true,
       .distributes = true,
       .analysis = false,
       .placeholders = {}},
      {.name = "simulate",
       .run = command_simulate,
       .summary = "delayspec simulate [SCENE]: a trajectory from the constant initial history: time series, Poincare points "
                "and impacts.",
       .out = OutDirUse::written,
       .resume = false,
       .distributes = false,
       .analysis = true,
       .placeholders = {}},
      {.name = "sweep",
       .run = command_sweep,
       .summary = "delayspec sweep [SCENE]: one parameter over a range; at each point the leading Lyapunov exponents and the "
                "Poincare section (bifurcation-diagram data).",
       .out = OutDirUse::written,  // point logs: --resume computes only the missing points
       .resume = true,
       .distributes = true,
       .analysis = true,
       .placeholders = {{"sweep_key", "(swept)"}, {"sweep_from", "0"}, {"sweep_to", "1"}}},
  };
  return table;
}

bool is_command(const std::string& name) {
  const auto& table = command_table();
  return std::any_of(table.begin(), table.end(), [&](const CommandSpec& spec) { return spec.name == name; });
}

std::string command_list() {
  std::string list;
  for (const auto& spec : command_table()) list += (list.empty() ? "" : ", ") + spec.name;
  return list;
}

const CommandSpec& command_spec(const std::string& name) {
  for (const auto& spec : command_table())
    if (spec.name == name) return spec;
  throw BadInput("unknown command `" + name + "` (commands: " + command_list() + ")");
}

void check_output_flags(const std::string& command, bool out_given, const std::string& out_dir, bool resume) {
  const CommandSpec& spec = command_spec(command);
  if (out_given && spec.out == OutDirUse::ignored)
    throw BadInput("`--out " + out_dir + "`: `" + command +
                   "` writes no files (its result is on stdout; `delayspec run SCENE --out DIR` keeps any "
                   "analysis's result in a file)");
  if (out_given && out_dir.empty()) throw BadInput("`--out ''`: the directory name is empty");
  if (resume && !spec.resume)
    throw BadInput("`--resume`: `" + command +
                   "` has nothing to resume (only sweep, chart, basin, and run with one of them, do)");
  if (resume && !out_given) throw BadInput("`--resume` needs `--out DIR` (the directory of the interrupted run)");
}

int run_command(Config& config, const Invocation& inv) {
  const CommandSpec& spec = command_spec(inv.command);
  config.set_reader(inv.command);
  config.set_key_index(&key_index);
  // Scene-level keys (for `run`): any command may be given a scene that has them.
  config.mark_used("analyses");
  config.mark_used("title");
  // Under mpirun the workers only compute points (ranks.hpp): the lead runs any other command
  // alone and owns --out (its lock and completeness marker).
  if (!is_lead_rank() && !spec.distributes) return 0;
  if (!inv.out_dir || spec.out != OutDirUse::written || !is_lead_rank()) return spec.run(config, inv);
  OutputDirectory directory(*inv.out_dir);  // held until the command returns: one run per DIR
  Invocation writing = inv;
  writing.output = &directory;
  int status = 0;
  try {
    status = spec.run(config, writing);
  } catch (const BadInput&) {
    directory.abandon();  // a run stopped by bad input leaves nothing behind (output_directory.hpp)
    throw;
  }
  directory.finish(inv.command, status);
  return status;
}

}  // namespace delayspec::cli
