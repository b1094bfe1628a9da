#pragma once
// Loads the symbolic front end of model = equations (libdelayspec_equations.so,
// src/modules/equations/equations_module.hpp) on first use (module_loader.hpp), so that a command that
// reads no [equations] table never maps GiNaC, CLN and GMP.
#include "modules/equations/equations_module.hpp"

namespace delayspec::cli {

// The module beside libdelayspec, loaded on the first call (thread-safe). BadInput (exit 2)
// naming the file when it is missing, cannot be loaded or is of another build (load_module).
const EquationsModule& equations_module();

// What the messages say of it (tests).
struct ModuleDescription;
const ModuleDescription& equations_module_description();

}  // namespace delayspec::cli
