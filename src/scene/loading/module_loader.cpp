#include "scene/loading/module_loader.hpp"


#include "delayspec/errors.hpp"
#include "engine/loading/shared_object.hpp"
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
  const detail::SharedObject module(file.string(), detail::Binding::now);
  if (!module.is_open())
    throw BadInput(needs(file, d) + ": it cannot be loaded (it needs " + d.dependencies + "): " + module.error());
  void* entry = module.function<void>(symbol);
  if (!entry) throw BadInput(needs(file, d) + ": it lacks `" + symbol + "`");
  return entry;
}

void check_module_version(const std::filesystem::path& file, const char* version, const ModuleDescription& d) {
  const std::string expected = detail::this_build();
  if (expected != version)
    throw BadInput(needs(file, d) + ": it is of delayspec " + version + ", this is " + expected +
                   ": rebuild or reinstall delayspec");
}

}  // namespace delayspec::cli
