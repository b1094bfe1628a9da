// The program's arguments -> one command of the table (scene/commands/commands.hpp) run through
// run_command; errors -> exit status and message. The one place that knows argv.
#include "cli/run_cli.hpp"

#include <exception>
#include <new>
#include <stdexcept>
#include <vector>

#include <CLI/CLI.hpp>

#include "delayspec/errors.hpp"
#include "delayspec/version.hpp"
#include "scene/commands/commands.hpp"
#include "scene/commands/key_registry.hpp"
#include "scene/points/ranks.hpp"

namespace delayspec::cli {

int run_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "delayspec: stability spectra (Floquet multipliers, Lyapunov exponents, characteristic roots) of delay "
      "differential equations, periodically forced or autonomous, matrix-free.\nCommands: " +
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
    if (is_command(command)) out << command_spec(command).summary << "\n\n";
    out << app.help();
    if (is_command(command)) out << command_keys_help(command);
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
    command_spec(command);  // BadInput naming the commands when it is none
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
