#include "linear_algebra.hpp"

#include <dlfcn.h>

#include <string>

#include "delayspec/errors.hpp"
#include "delayspec/linear_algebra_libraries.hpp"

// The libraries' shared-object names (SONAMEs), found at configure time from the libraries CMake
// found (CMakeLists.txt): the same libraries a link would have recorded.
#if !defined(DELAYSPEC_BLAS_SONAME) || !defined(DELAYSPEC_LAPACK_SONAME) || !defined(DELAYSPEC_ARPACK_SONAME) || \
    !defined(DELAYSPEC_UMFPACK_SONAME)
#error "the build defines the linear-algebra libraries' SONAMEs (CMakeLists.txt)"
#endif

namespace delayspec {

namespace {

struct Loaded {
  detail::LinearAlgebra functions;
  std::string error;  // empty when every library and entry point was found
};

// dlopen by SONAME, as the loader would have found a linked library. RTLD_LAZY, as at start-up:
// RTLD_NOW binds every call of LAPACK's thousands of routines at once and made the load 3 ms
// instead of 2 (measured at N = 2000, docs/benchmarks.md "Eighth sitting"). RTLD_LOCAL: their
// symbols stay out of the process's global scope (a Python process may hold another BLAS).
void* open_library(const char* soname, const char* what, std::string& error) {
  void* handle = dlopen(soname, RTLD_LAZY | RTLD_LOCAL);
  if (!handle && error.empty()) {
    const char* reason = dlerror();
    error = std::string("cannot load ") + soname + " (" + what + "): " + (reason ? reason : "unknown reason") +
            "; scripts/setup-debian.sh installs it";
  }
  return handle;
}

template <class F>
void find_function(void* handle, const char* soname, const char* name, F*& function, std::string& error) {
  if (!handle) return;
  function = reinterpret_cast<F*>(dlsym(handle, name));
  if (!function && error.empty()) error = std::string(soname) + " has no function " + name;
}

Loaded load() {
  Loaded l;
  detail::LinearAlgebra& f = l.functions;
  void* blas = open_library(DELAYSPEC_BLAS_SONAME, "BLAS", l.error);
  find_function(blas, DELAYSPEC_BLAS_SONAME, "dgemm_", f.dgemm, l.error);
  void* lapack = open_library(DELAYSPEC_LAPACK_SONAME, "LAPACK", l.error);
  find_function(lapack, DELAYSPEC_LAPACK_SONAME, "dgeev_", f.dgeev, l.error);
  find_function(lapack, DELAYSPEC_LAPACK_SONAME, "dgees_", f.dgees, l.error);
  void* arpack = open_library(DELAYSPEC_ARPACK_SONAME, "ARPACK-ng", l.error);
  find_function(arpack, DELAYSPEC_ARPACK_SONAME, "dnaupd_c", f.dnaupd_c, l.error);
  find_function(arpack, DELAYSPEC_ARPACK_SONAME, "dneupd_c", f.dneupd_c, l.error);
  void* umfpack = open_library(DELAYSPEC_UMFPACK_SONAME, "SuiteSparse UMFPACK", l.error);
  find_function(umfpack, DELAYSPEC_UMFPACK_SONAME, "umfpack_di_defaults", f.umfpack_di_defaults, l.error);
  find_function(umfpack, DELAYSPEC_UMFPACK_SONAME, "umfpack_di_symbolic", f.umfpack_di_symbolic, l.error);
  find_function(umfpack, DELAYSPEC_UMFPACK_SONAME, "umfpack_di_numeric", f.umfpack_di_numeric, l.error);
  find_function(umfpack, DELAYSPEC_UMFPACK_SONAME, "umfpack_di_solve", f.umfpack_di_solve, l.error);
  find_function(umfpack, DELAYSPEC_UMFPACK_SONAME, "umfpack_di_free_symbolic", f.umfpack_di_free_symbolic, l.error);
  find_function(umfpack, DELAYSPEC_UMFPACK_SONAME, "umfpack_di_free_numeric", f.umfpack_di_free_numeric, l.error);
  // The handles are never closed: the libraries stay for the process's life, as linked ones do.
  return l;
}

// Loaded once per process (a function-local static: a second thread waits for the first).
const Loaded& loaded() {
  static const Loaded l = load();
  return l;
}

}  // namespace

const detail::LinearAlgebra& detail::linear_algebra() {
  const Loaded& l = loaded();
  if (!l.error.empty()) throw BadInput(l.error);
  return l.functions;
}

void load_linear_algebra() { detail::linear_algebra(); }

}  // namespace delayspec
