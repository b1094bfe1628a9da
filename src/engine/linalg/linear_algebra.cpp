#include "engine/linalg/linear_algebra.hpp"

#include <string>

#include "delayspec/errors.hpp"
#include "delayspec/linear_algebra_libraries.hpp"
#include "engine/loading/shared_object.hpp"

// The libraries' shared-object names (SONAMEs), found at configure time from the libraries CMake
// found (CMakeLists.txt): the same libraries a link would have recorded.
#if !defined(DELAYSPEC_BLAS_SONAME) || !defined(DELAYSPEC_LAPACK_SONAME) || !defined(DELAYSPEC_ARPACK_SONAME) || \
    !defined(DELAYSPEC_UMFPACK_SONAME)
#error "the build defines the linear-algebra libraries' SONAMEs (CMakeLists.txt)"
#endif

namespace delayspec {

namespace {

// By SONAME, as the loader would have found a linked library. Bound lazily, as at start-up:
// binding every call of LAPACK's thousands of routines at once made the load 3 ms instead of 2
// (measured at N = 2000, docs/benchmarks.md "Eighth sitting").
detail::SharedObject open_library(const char* soname, const char* what, std::string& error) {
  detail::SharedObject library(soname, detail::Binding::lazy);
  if (!library.is_open() && error.empty())
    error = std::string("cannot load ") + soname + " (" + what + "): " + library.error() +
            "; scripts/setup-debian.sh installs it";
  return library;
}

template <class F>
void find_function(const detail::SharedObject& library, const char* soname, const char* name, F*& function,
                   std::string& error) {
  if (!library.is_open()) return;
  function = library.function<F>(name);
  if (!function && error.empty()) error = std::string(soname) + " has no function " + name;
}

// A table filled by fill(table, error) once per process (a function-local static of each
// instantiation: a second thread waits for the first); the handles are never closed, the
// libraries stay for the process's life as linked ones do.
template <class Table, class Fill>
const Table& loaded_once(Fill fill) {
  struct Loaded {
    Table functions;
    std::string error;  // empty when the library and every entry point were found
  };
  static const Loaded l = [&] {
    Loaded r;
    fill(r.functions, r.error);
    return r;
  }();
  if (!l.error.empty()) throw BadInput(l.error);
  return l.functions;
}

}  // namespace

const detail::Lapack& detail::lapack() {
  return loaded_once<Lapack>([](Lapack& f, std::string& error) {
    const auto blas = open_library(DELAYSPEC_BLAS_SONAME, "BLAS", error);
    find_function(blas, DELAYSPEC_BLAS_SONAME, "dgemm_", f.dgemm, error);
    const auto lapack = open_library(DELAYSPEC_LAPACK_SONAME, "LAPACK", error);
    find_function(lapack, DELAYSPEC_LAPACK_SONAME, "dgeev_", f.dgeev, error);
    find_function(lapack, DELAYSPEC_LAPACK_SONAME, "dgees_", f.dgees, error);
    find_function(lapack, DELAYSPEC_LAPACK_SONAME, "zgesvd_", f.zgesvd, error);
  });
}

const detail::Arpack& detail::arpack() {
  return loaded_once<Arpack>([](Arpack& f, std::string& error) {
    const auto arpack = open_library(DELAYSPEC_ARPACK_SONAME, "ARPACK-ng", error);
    find_function(arpack, DELAYSPEC_ARPACK_SONAME, "dnaupd_c", f.dnaupd_c, error);
    find_function(arpack, DELAYSPEC_ARPACK_SONAME, "dneupd_c", f.dneupd_c, error);
  });
}

const detail::Umfpack& detail::umfpack() {
  return loaded_once<Umfpack>([](Umfpack& f, std::string& error) {
    const char* so = DELAYSPEC_UMFPACK_SONAME;
    const auto umfpack = open_library(so, "SuiteSparse UMFPACK", error);
    find_function(umfpack, so, "umfpack_di_defaults", f.di_defaults, error);
    find_function(umfpack, so, "umfpack_di_symbolic", f.di_symbolic, error);
    find_function(umfpack, so, "umfpack_di_numeric", f.di_numeric, error);
    find_function(umfpack, so, "umfpack_di_solve", f.di_solve, error);
    find_function(umfpack, so, "umfpack_di_free_symbolic", f.di_free_symbolic, error);
    find_function(umfpack, so, "umfpack_di_free_numeric", f.di_free_numeric, error);
  });
}

void load_linear_algebra() {
  detail::lapack();
  detail::arpack();
  detail::umfpack();
}

}  // namespace delayspec
