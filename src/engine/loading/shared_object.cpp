#include "engine/loading/shared_object.hpp"

#include <dlfcn.h>

#include "delayspec/version.hpp"

namespace delayspec::detail {

SharedObject::SharedObject(const std::string& file, Binding binding)
    : handle_(dlopen(file.c_str(), (binding == Binding::lazy ? RTLD_LAZY : RTLD_NOW) | RTLD_LOCAL)) {
  if (!handle_) {
    const char* reason = dlerror();
    error_ = reason ? reason : "unknown reason";
  }
}

void* SharedObject::address(const char* name) const { return handle_ ? dlsym(handle_, name) : nullptr; }

std::string this_build() { return std::string(DELAYSPEC_VERSION) + " " + DELAYSPEC_REVISION; }

}  // namespace delayspec::detail
