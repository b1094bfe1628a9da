#pragma once
// The delayspec program's command line (main.cpp; the CLI tests run it in-process).
#include <ostream>

namespace delayspec::cli {

// Runs the program: parses argv, dispatches through run_command, maps errors to exit codes
// (0; 2 bad input; 3 numerical failure, out of memory, internal error). Never throws.
int run_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace delayspec::cli
