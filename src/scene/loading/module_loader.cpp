#include "scene/loading/module_loader.hpp"

#include <dlfcn.h>

#include "delayspec/errors.hpp"
#include "delayspec/version.hpp"
#include "scene/loading/running_library.hpp"

namespace delayspec::cli {

namespace {

std::string needs(const std::filesystem::path& file, const ModuleDescription& d) {
  return d.needed_by + " needs the module " + file.string() + " (" + d.what + ")";
}

}  // namespace

std::filesystem::path module_file(const std::string& name) { return running_library().parent_path() / name; }

void* load_module_entry(const std::filesystem::path& file, const char* symbol, const ModuleDescription& d) {
  if (!std::filesystem::exists(file))
    throw BadInput(needs(file, d) + ": it is missing (build or reinstall delayspec: the module is one of its targets)");
  // RTLD_LOCAL: the module's libraries stay out of the global scope. Never dlclose'd: they keep
  // static objects whose destructors run at exit.
  void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) throw BadInput(needs(file, d) + ": it cannot be loaded (it needs " + d.dependencies + "): " + dlerror());
  void* entry = dlsym(handle, symbol);
  if (!entry) throw BadInput(needs(file, d) + ": it lacks `" + symbol + "`");
  return entry;
}

void check_module_version(const std::filesystem::path& file, const char* version, const ModuleDescription& d) {
  const std::string expected = std::string(DELAYSPEC_VERSION) + " " + DELAYSPEC_REVISION;
  if (expected != version)
    throw BadInput(needs(file, d) + ": it is of delayspec " + version + ", this is " + expected +
                   ": rebuild or reinstall delayspec");
}

}  // namespace delayspec::cli
