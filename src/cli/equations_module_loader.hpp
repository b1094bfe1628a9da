#pragma once
// Loads the symbolic front end of model = equations (libdelayspec_equations.so,
// src/equations/equations_module.hpp) on first use, so that a command that reads no [equations]
// table never maps GiNaC, CLN and GMP.
#include <filesystem>

#include "equations_module.hpp"

namespace delayspec::cli {

// The module beside the libdelayspec this process runs (running_library.hpp): build/ in the
// build tree, the prefix's lib directory once installed; the program, the tests and the Python
// module all find it there. Loaded once (thread-safe), never unloaded. BadInput (exit 2) as
// load_equations_module.
const EquationsModule& equations_module();

// The module at `file`. BadInput naming the file when it is missing or cannot be loaded (dlerror
// says why, e.g. a missing libginac), lacks the entry point, or is of another delayspec build.
const EquationsModule& load_equations_module(const std::filesystem::path& file);

}  // namespace delayspec::cli
