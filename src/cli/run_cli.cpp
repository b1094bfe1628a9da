#include <exception>
#include <map>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/version.hpp"
#include "key_registry.hpp"

namespace delayspec::cli {

const std::map<std::string, CommandFunction>& command_table() {
  static const std::map<std::string, CommandFunction> table = {
      {"floquet", command_floquet},
      {"lyapunov", command_lyapunov},
      {"sweep", command_sweep},
      {"converge", command_converge},
      {"bench", command_bench},
      {"run", command_run},
      {"chart", command_chart},
      {"basin", command_basin},
      {"plot", command_plot},
      {"simulate", command_simulate},
  };
  return table;
}

namespace {

std::string command_list() {
  std::string list;
  for (const auto& [name, fn] : command_table()) list += (list.empty() ? "" : ", ") + name;
  return list;
}

}  // namespace

int run_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{"delayspec: stability spectra (Floquet multipliers, Lyapunov exponents) of periodically forced "
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
  app.add_option("--out", out_dir, "directory for output files");
  app.add_flag("--quiet", quiet, "no progress on stderr");
  app.add_flag("--resume", resume, "continue an interrupted run in --out");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
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

  auto it = command_table().find(command);
  if (it == command_table().end()) {
    err << "delayspec: error: unknown command `" << command << "` (commands: " << command_list() << ")\n";
    return 2;
  }
  Invocation inv{.command = command,
                 .scene = scene.empty() ? std::nullopt : std::optional<std::string>(scene),
                 .json = json,
                 .out_dir = out_dir.empty() ? std::nullopt : std::optional<std::string>(out_dir),
                 .quiet = quiet,
                 .resume = resume,
                 .out = out,
                 .err = err};
  try {
    // `plot DIR`: the positional argument is a results directory, not a scene.
    Config config = scene.empty() || command == "plot" ? Config() : Config::from_scene_file(scene);
    for (const auto& a : assignments) config.set_from_assignment(a);
    config.set_reader(command);
    // Scene-level keys (for `run`): any command may be given a scene that has them.
    config.mark_used("analyses");
    config.mark_used("title");
    return it->second(config, inv);
  } catch (const BadInput& e) {
    err << "delayspec " << command << ": bad input: " << e.what() << "\n";
    return 2;
  } catch (const NumericalFailure& e) {
    err << "delayspec " << command << ": numerical failure: " << e.what() << "\n";
    return 3;
  } catch (const std::bad_alloc&) {
    err << "delayspec " << command << ": out of memory (reduce N or use a Krylov solver)\n";
    return 3;
  } catch (const std::exception& e) {
    err << "delayspec " << command << ": internal error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace delayspec::cli
