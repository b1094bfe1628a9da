#pragma once
// The one place delayspec opens a shared object and looks up its functions: the linear-algebra
// libraries (by SONAME, engine/linalg/linear_algebra.hpp), the two modules beside libdelayspec
// (scene/loading/module_loader.hpp) and the models compiled from a scene's equations
// (scene/equations/equation_plugin.hpp). Each caller words its own message; what is shared is
// the opening, the typed lookup and what a build's version is.
//
// An object is opened RTLD_LOCAL (its symbols stay out of the process's global scope: a Python
// process may hold another BLAS) and never closed: the objects keep static objects whose
// destructors run at exit, and the linear-algebra libraries stay for the process's life as linked
// ones do.
#include <string>

namespace delayspec::detail {

// When the dynamic loader binds the object's calls: at the first call of each (lazy: LAPACK's
// thousands of routines would otherwise all be bound at load), or all at load (now: a module or
// model whose missing symbol must show at load, not in the middle of a run).
enum class Binding { lazy, now };

class SharedObject {
 public:
  // dlopen(file): a path, a SONAME (searched as the loader searches for a linked library), or
  // /proc/self/fd/N. Not open when it cannot be loaded: error() says why (the loader's message).
  SharedObject(const std::string& file, Binding binding);
  bool is_open() const { return handle_ != nullptr; }
  const std::string& error() const { return error_; }

  // The function `name` of the object, as the type F the caller knows it by (the object's side
  // checks that type where it defines the function); null when the object lacks it.
  template <class F>
  F* function(const char* name) const {
    return reinterpret_cast<F*>(address(name));
  }

 private:
  void* address(const char* name) const;
  void* handle_ = nullptr;
  std::string error_;
};

// DELAYSPEC_VERSION " " DELAYSPEC_REVISION: what a module or compiled model of this very build
// reports. Their tables have C++ types, so only one build's objects go together.
std::string this_build();

}  // namespace delayspec::detail
