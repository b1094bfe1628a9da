#include "equations_module_loader.hpp"

#include <dlfcn.h>

#include <string>

#include "delayspec/errors.hpp"
#include "delayspec/version.hpp"
#include "running_library.hpp"

namespace delayspec::cli {

const EquationsModule& load_equations_module(const std::filesystem::path& file) {
  const std::string needs = "model = equations needs the module " + file.string() + " (delayspec's symbolic front end)";
  if (!std::filesystem::exists(file))
    throw BadInput(needs + ": it is missing (build the target delayspec_equations, or reinstall delayspec)");
  // RTLD_LOCAL: GiNaC's symbols stay out of the global scope. Never dlclose'd: GiNaC keeps
  // static objects whose destructors run at exit.
  void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle)
    throw BadInput(needs + ": it cannot be loaded (it needs GiNaC, Debian package libginac-dev): " + dlerror());
  const auto entry = reinterpret_cast<EquationsModuleEntry>(dlsym(handle, equations_module_symbol));
  if (!entry) throw BadInput(needs + ": it lacks `" + equations_module_symbol + "`");
  const EquationsModule* module = entry();
  // The table's members have C++ types: only the build that made this program may provide them.
  const std::string expected = std::string(DELAYSPEC_VERSION) + " " + DELAYSPEC_REVISION;
  if (expected != module->version)
    throw BadInput(needs + ": it is of delayspec " + module->version + ", this is " + expected +
                   ": rebuild or reinstall delayspec");
  return *module;
}

const EquationsModule& equations_module() {
  // A function-local static: initialised once, under the compiler's lock; a failed load throws
  // and is tried again at the next call.
  static const EquationsModule& module = load_equations_module(running_library().parent_path() / equations_module_file);
  return module;
}

}  // namespace delayspec::cli
