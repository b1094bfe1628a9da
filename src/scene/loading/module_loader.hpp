#pragma once
// The modules delayspec loads with dlopen on first use, so that a process that does not need
// them never maps their libraries (each costs start-up: docs/benchmarks.md, "Start-up"):
// libdelayspec_equations (GiNaC, for model = equations: src/modules/equations/equations_module.hpp) and
// libdelayspec_mpi (OpenMPI, under an MPI launcher: src/modules/mpi/mpi_module.hpp). Both lie beside the
// libdelayspec this process runs (running_library.hpp): build/ in the build tree, the prefix's
// lib directory once installed, for the program, the tests and the Python module alike.
//
// A module exports one C function, `symbol`, that returns its table: the module's version
// (DELAYSPEC_VERSION " " DELAYSPEC_REVISION), then functions with C++ types, which only the
// build that made this program may provide. Loaded once, never unloaded.
#include <filesystem>
#include <string>

namespace delayspec::cli {

// What the messages say of a module.
struct ModuleDescription {
  std::string needed_by;     // what needs it: "model = equations"
  std::string what;          // "delayspec's symbolic front end"
  std::string dependencies;  // the libraries it loads, with their Debian package, for a failed load
};

// The file `name` beside libdelayspec.
std::filesystem::path module_file(const std::string& name);

// The table the module at `file` returns from its entry point `symbol`, its version checked.
// BadInput naming the file when it is missing or cannot be loaded (dlerror says why, e.g. a
// missing library of the module's), lacks the entry point, or is of another delayspec build.
// Table: a struct whose first member is `const char* version`.
template <class Table>
const Table& load_module(const std::filesystem::path& file, const char* symbol, const ModuleDescription& description);

// The untyped part of load_module: the address of the entry point, a `const Table* ()` function.
void* load_module_entry(const std::filesystem::path& file, const char* symbol, const ModuleDescription& description);
// BadInput unless `version` is this program's.
void check_module_version(const std::filesystem::path& file, const char* version, const ModuleDescription& description);

template <class Table>
const Table& load_module(const std::filesystem::path& file, const char* symbol, const ModuleDescription& description) {
  // The entry point's type is checked where the module defines it (equations_module.cpp, mpi_module.cpp).
  const auto entry = reinterpret_cast<const Table* (*)()>(load_module_entry(file, symbol, description));
  const Table* table = entry();
  check_module_version(file, table->version, description);
  return *table;
}

}  // namespace delayspec::cli
