#pragma once
// One run of a command as the front end asked for it (the program's arguments, or the Python
// module's call): which command, where its output goes (text or one JSON object on `out`, the
// --out directory, progress and warnings on `err`).
#include <optional>
#include <ostream>
#include <string>

#include <nlohmann/json_fwd.hpp>

namespace delayspec::cli {

class OutputDirectory;  // output_directory.hpp

struct Invocation {
  std::string command;
  std::optional<std::string> scene;
  bool json = false;
  std::optional<std::string> out_dir;
  bool quiet = false;
  bool resume = false;
  std::ostream& out;
  std::ostream& err;
  // Bulk results the JSON leaves to --out files, for a front end that takes values (the Python
  // module): when set, `simulate` puts its trajectory rows here under "trajectory".
  nlohmann::json* arrays = nullptr;
  // The --out directory's lock and completeness marker, held by run_command while the command
  // writes there (output_directory.hpp); null when the command writes no files or runs alone.
  OutputDirectory* output = nullptr;
};

}  // namespace delayspec::cli
