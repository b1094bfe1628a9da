#pragma once
// The symbolic front end of model = equations (this directory: GiNaC, CLN, GMP) is a shared
// module of its own, libdelayspec_equations.so, loaded with dlopen the first time a scene has
// model = equations (src/scene/equations/equations_module_loader.hpp, module_loader.hpp). Linked into the program, GiNaC's and
// CLN's static initialisation (1.5 ms) and the loading of the three libraries were paid by every
// command, `--version` included (docs/benchmarks.md, "Start-up").
//
// The module exports one C symbol, equations_module_symbol, a function that returns this table.
// Its members have C++ types (the table of a scene, the source it becomes): the module and the
// program must come from one build, which the loader checks with `version`.
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "modules/equations/equation_model_source.hpp"

namespace delayspec::cli {

struct EquationsModule {
  // DELAYSPEC_VERSION " " DELAYSPEC_REVISION of the module's build (delayspec/version.hpp).
  const char* version = nullptr;
  // generate_equation_model (equation_model_source.hpp). Not thread-safe (GiNaC).
  EquationModelSource (*generate)(const toml::table& equations,
                                  const std::vector<std::string>& reserved_keys) = nullptr;
};

// The module's file name, beside libdelayspec (build tree and installed alike).
inline constexpr char equations_module_file[] = "libdelayspec_equations.so";
// extern "C" const EquationsModule* delayspec_equations_module(): the table, static in the module.
inline constexpr char equations_module_symbol[] = "delayspec_equations_module";

}  // namespace delayspec::cli
