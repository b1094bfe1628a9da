#include <exception>
#include <new>
#include <stdexcept>
#include <map>
#include <vector>

#include <CLI/CLI.hpp>

#include "scene/commands/commands.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/version.hpp"
#include "scene/points/distributed_points.hpp"
#include "scene/commands/key_registry.hpp"
#include "scene/output/output_directory.hpp"
#include "scene/points/ranks.hpp"

namespace delayspec::cli {

const std::map<std::string, CommandFunction>& command_table() {
  static const std::map<std::string, CommandFunction> table = {
      {"floquet", command_floquet},   {"lyapunov", command_lyapunov}, {"sweep", command_sweep},
      {"converge", command_converge}, {"bench", command_bench},       {"run", command_run},
      {"chart", command_chart},       {"basin", command_basin},       {"plot", command_plot},
      {"simulate", command_simulate}, {"continue", command_continue},
  };
  return table;
}

const std::string& command_summary(const std::string& command) {
  static const std::map<std::string, std::string> summaries = {
      {"floquet",
       "delayspec floquet [SCENE]: the leading Floquet multipliers of the periodic orbit, each with its distance to "
       "the N -> infinity value, and a verdict: stable, unstable or undecided."},
      {"lyapunov",
       "delayspec lyapunov [SCENE]: the leading Lyapunov exponents of a trajectory from the constant initial "
       "history, with their statistical errors."},
      {"sweep",
       "delayspec sweep [SCENE]: one parameter over a range; at each point the leading Lyapunov exponents and the "
       "Poincare section (bifurcation-diagram data)."},
      {"converge",
       "delayspec converge [SCENE]: the leading multipliers at several N: their errors, the observed order and the "
       "Richardson extrapolation to N -> infinity."},
      {"bench",
       "delayspec bench [SCENE]: speed against error, the Krylov and the dense eigensolvers side by side at several "
       "N."},
      {"chart", "delayspec chart [SCENE]: a stability chart, the spectral radius |mu_1| over a grid of two parameters."},
      {"basin",
       "delayspec basin [SCENE]: basins of attraction, the attractor (its period) reached from each constant initial "
       "history of a grid."},
      {"plot",
       "delayspec plot DIR: figures (PNG, SVG and their gnuplot scripts) of the results a command wrote in DIR, into "
       "DIR/plots/."},
      {"simulate",
       "delayspec simulate [SCENE]: a trajectory from the constant initial history: time series, Poincare points "
       "and impacts."},
      {"continue",
       "delayspec continue [SCENE]: the periodic orbit continued in one parameter, its bifurcations located and "
       "extrapolated to N -> infinity."},
      {"run", "delayspec run SCENE --out DIR: the analyses the scene lists, each result kept as a file in DIR."},
  };
  static const std::string none;
  auto it = summaries.find(command);
  return it == summaries.end() ? none : it->second;
}

OutputUse output_use(const std::string& command) {
  static const std::map<std::string, OutputUse> table = {
      {"sweep", {OutDirUse::written, true}},  // point files: --resume computes only the missing points
      {"run", {OutDirUse::written, true}},    // passes --resume to its analyses (command_run.cpp)
      {"converge", {OutDirUse::written, false}}, {"bench", {OutDirUse::written, false}},
      {"chart", {OutDirUse::written, true}},     {"basin", {OutDirUse::written, true}},  // point files, as sweep
      {"simulate", {OutDirUse::written, false}}, {"continue", {OutDirUse::written, false}},
      {"plot", {OutDirUse::read, false}},  // `plot --out DIR` = `plot DIR`
  };
  auto it = table.find(command);
  return it == table.end() ? OutputUse{} : it->second;  // floquet, lyapunov: results on stdout only
}

void check_output_flags(const std::string& command, bool out_given, const std::string& out_dir, bool resume) {
  const OutputUse use = output_use(command);
  if (out_given && use.out == OutDirUse::ignored)
    throw BadInput("`--out " + out_dir + "`: `" + command +
                   "` writes no files (its result is on stdout; `delayspec run SCENE --out DIR` keeps any "
                   "analysis's result in a file)");
  if (out_given && out_dir.empty()) throw BadInput("`--out ''`: the directory name is empty");
  if (resume && !use.resume)
    throw BadInput("`--resume`: `" + command +
                   "` has nothing to resume (only sweep, chart, basin, and run with one of them, do)");
  if (resume && !out_given) throw BadInput("`--resume` needs `--out DIR` (the directory of the interrupted run)");
}

int run_command(Config& config, const Invocation& inv) {
  const CommandFunction command = command_table().at(inv.command);
  config.set_reader(inv.command);
  config.set_key_index(key_index());
  // Scene-level keys (for `run`): any command may be given a scene that has them.
  config.mark_used("analyses");
  config.mark_used("title");
  // Under mpirun the workers only compute points (ranks.hpp): the lead runs any other command
  // alone and owns --out (its lock and completeness marker).
  if (!is_lead_rank() && !distributes_points(inv.command)) return 0;
  if (!inv.out_dir || output_use(inv.command).out != OutDirUse::written || !is_lead_rank()) return command(config, inv);
  OutputDirectory directory(*inv.out_dir);  // held until the command returns: one run per DIR
  int status = 0;
  try {
    status = command(config, inv);
  } catch (const BadInput&) {
    directory.abandon();  // a run stopped by bad input leaves nothing behind (output_directory.hpp)
    throw;
  }
  directory.finish(inv.command, status);
  return status;
}

namespace {

std::string command_list() {
  std::string list;
  for (const auto& [name, fn] : command_table()) list += (list.empty() ? "" : ", ") + name;
  return list;
}

}  // namespace

void require_known_command(const std::string& command) {
  if (!command_table().count(command))
    throw BadInput("unknown command `" + command + "` (commands: " + command_list() + ")");
}

int run_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "delayspec: stability spectra (Floquet multipliers, Lyapunov exponents) of periodically forced "
      "delay differential equations, matrix-free.\nCommands: " +
      command_list()};
  app.set_version_flag("--version", std::string("delayspec ") + DELAYSPEC_VERSION);
  std::string command;
  std::string scene;
  std::vector<std::string> assignments;
  std::string out_dir;
  bool json = false, quiet = false, resume = false;
  app.add_option("command", command, "command: " + command_list())->required();
  app.add_option("scene", scene, "scene file (TOML); optional");
  app.add_option("--set", assignments, "override a scene key: --set KEY=VALUE (repeatable, applied in order)")
      ->take_last()
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app.add_flag("--json", json, "print exactly one JSON object on stdout");
  CLI::Option* out_option = app.add_option("--out", out_dir, "directory for output files");
  app.add_flag("--quiet", quiet, "no progress on stderr");
  app.add_flag("--resume", resume, "continue an interrupted run in --out");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    if (command_table().count(command)) out << command_summary(command) << "\n\n";
    out << app.help();
    if (command_table().count(command)) out << command_keys_help(command);
    else out << "\n`delayspec COMMAND --help` lists the keys COMMAND reads, with their defaults.\n";
    return 0;
  } catch (const CLI::CallForVersion& e) {
    out << "delayspec " << DELAYSPEC_VERSION << "\n";
    return 0;
  } catch (const CLI::ParseError& e) {
    err << "delayspec: error: " << e.what() << "\n";
    return 2;
  }

  try {
    require_known_command(command);
  } catch (const BadInput& e) {
    err << "delayspec: error: " << e.what() << "\n";
    return 2;
  }
  Invocation inv{.command = command,
                 .scene = scene.empty() ? std::nullopt : std::optional<std::string>(scene),
                 .json = json,
                 .out_dir = out_dir.empty() ? std::nullopt : std::optional<std::string>(out_dir),
                 .quiet = quiet || !is_lead_rank(),  // progress from the lead only
                 .resume = resume,
                 .out = out,
                 .err = err};
  // Exit status 0, 2 (bad input) or 3 (numerical failure, out of memory, internal error): never 1,
  // which scripts could not tell from a crash of the shell around it.
  Config config;
  try {
    const bool out_given = out_option->count() > 0;
    check_output_flags(command, out_given, out_dir, resume);
    // `plot DIR`: the positional argument is a results directory, not a scene.
    if (!scene.empty() && command != "plot") config = Config::from_scene_file(scene);
    for (const auto& a : assignments) config.set_from_assignment(a);
    return run_command(config, inv);
  } catch (const BadInput& e) {
    err << "delayspec " << command << ": bad input: " << e.what() << "\n";
    return 2;
  } catch (const NumericalFailure& e) {
    err << "delayspec " << command << ": numerical failure: " << e.what() << "\n";
    return 3;
  } catch (const std::bad_alloc&) {
    // The Krylov hint only where a dense solver was asked for (bench compares dense by default).
    const std::string solver = config.values().count("solver") ? config.values().at("solver") : "";
    const bool dense = solver.rfind("dense", 0) == 0 || command == "bench";
    err << "delayspec " << command << ": out of memory (reduce N" << (dense ? " or use a Krylov solver" : "") << ")\n";
    return 3;
  } catch (const std::length_error& e) {
    err << "delayspec " << command << ": out of memory: a buffer larger than the address space (" << e.what()
        << "); reduce N or the run's length\n";
    return 3;
  } catch (const std::exception& e) {
    err << "delayspec " << command << ": internal error (please report): " << e.what() << "\n";
    return 3;
  }
}

}  // namespace delayspec::cli
