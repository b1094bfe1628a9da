#include "scene/equations/equations_module_loader.hpp"

#include "scene/loading/module_loader.hpp"

namespace delayspec::cli {

const ModuleDescription& equations_module_description() {
  static const ModuleDescription description{"model = equations", "delayspec's symbolic front end",
                                             "GiNaC, Debian package libginac11"};
  return description;
}

const EquationsModule& equations_module() {
  // A function-local static: initialised once, under the compiler's lock; a failed load throws
  // and is tried again at the next call.
  static const EquationsModule& module = load_module<EquationsModule>(
      module_file(equations_module_file), equations_module_symbol, equations_module_description());
  return module;
}

}  // namespace delayspec::cli
