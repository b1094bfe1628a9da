#include "scene/loading/running_library.hpp"

#include <dlfcn.h>

#include "delayspec/errors.hpp"
#include "delayspec/grid.hpp"

namespace delayspec::cli {

std::filesystem::path running_library() {
  // regrid: any function defined in libdelayspec; dladdr names the object that holds it.
  HistoryGrid (*const in_library)(const HistoryGrid&, int) = &regrid;
  Dl_info info{};
  if (!dladdr(reinterpret_cast<const void*>(in_library), &info) || !info.dli_fname)
    throw BadInput("cannot locate the delayspec library of this process (dladdr)");
  return std::filesystem::canonical(info.dli_fname);
}

}  // namespace delayspec::cli
