#pragma once
// The delayspec command line run in-process (run_cli, as main() does), for the CLI tests:
// exit status and everything written to stdout and stderr.
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"

namespace delayspec::testing {

struct CliResult {
  int status;
  std::string out, err;
};

// `args` without the program name, e.g. {"floquet", scene, "--json", "--set", "N=40"}.
inline CliResult run(std::vector<std::string> args) {
  args.insert(args.begin(), "delayspec");
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  const int status = delayspec::cli::run_cli(static_cast<int>(argv.size()), argv.data(), out, err);
  return {status, out.str(), err.str()};
}

}  // namespace delayspec::testing
