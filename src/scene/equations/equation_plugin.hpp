#pragma once
// A model compiled at run time. The functions printed from a scene's equations
// (equation_model_source.hpp: only code GiNaC printed from parsed expressions) are wrapped in a
// translation unit, compiled with the compiler that built delayspec against its headers into a
// shared object that links this same libdelayspec, and loaded with dlopen. The analyses are those
// of FunctionModel<shape> (function_model.hpp): taken from libdelayspec_prebuilt when the shape
// is one of prebuilt_shapes.hpp and that library is built (the unit is then the functions alone,
// under a second), else instantiated in the unit (about 20 s). Nothing is interpreted per step:
// the model's functions are compiled code, called once per evaluation, with d fixed.
//
// Cache (model_cache.hpp: a directory private to the user, entries never opened through a link):
// DIR/eq-HASH.so beside its source DIR/eq-HASH.cpp, its checksum DIR/eq-HASH.sum and the
// compiler's log DIR/eq-HASH.log; DIR/tx-HASH2.table records which object a table's text gave. HASH covers the source, delayspec's version and revision, the
// compiler (path, size, time), the library it links (path, size, time) and the contents of
// delayspec's headers it is compiled against. A hit needs the stored source equal to this one (so
// not even a hash collision loads another model) and the object's bytes equal to the checksum
// recorded when this program compiled it; the object is then opened through the descriptor whose
// bytes were checked. Concurrent first runs (threads, MPI ranks, processes) take an flock on
// DIR/eq-HASH.lock: one compiles, into a temporary object that is loaded and checked before it is
// renamed into place, the others wait and load its object. The compiler runs as a child that dies
// with delayspec and within a time limit (child_process.hpp). A loaded object is never unloaded
// (its code runs the analyses it made).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "delayspec/model_analyses.hpp"
#include "delayspec/model_functions.hpp"

namespace delayspec::cli {

struct EquationPlugin {
  // The analyses of the model at the given parameter values (in the order of the source's
  // parameters), delays (in the order of the source's delays), period and constant initial
  // history (d values). The caller owns it.
  ModelAnalyses* (*analyses)(const double* parameters, const double* delays, double period,
                             const double* history) = nullptr;
  double (*period)(const double* parameters) = nullptr;                // the `period` expression
  void (*delays)(const double* parameters, double* delays) = nullptr;  // the `delay(s)` expressions
  void (*history)(const double* parameters, double* state) = nullptr;  // the `history` expressions
  std::filesystem::path object;                                        // the loaded shared object
};

// Loads the model whose printed functions are `model_code`, of the shape `shape`, compiling it into `cache_dir` first
// unless a cached object exists. The compiler is the one that built delayspec, or the program
// the environment variable DELAYSPEC_CXX names. BadInput (exit 2) when there is no compiler
// (naming the Debian package), when the code does not compile (with the compiler's first lines)
// and when the cache cannot be written or the object not loaded. Reports on stderr when it
// compiles, and how long that took.
// `record` is kept beside the object (DIR/tx-HASH.table), so that a later run of the same table
// finds the model by found_equation_plugin, without GiNaC.
struct TableRecord {
  std::string table_text;  // the [equations] table as the scene gave it
  std::string names;       // what the caller needs of the model besides its code, as text
};
EquationPlugin load_equation_plugin(const std::string& model_code, const ModelShape& shape,
                                    const std::filesystem::path& cache_dir, const TableRecord& record);

// The model this program compiled from the table `table_text` into `cache_dir` (same program,
// compiler, library and headers: the entry's hash), with the names recorded then: found from the
// table's text alone, so a cached model costs no symbolic work. The object is checked as a cache
// hit of load_equation_plugin is. Nothing when there is no such record or any part of it or of
// the object is missing or differs: the caller reads the table and loads the model as above.
struct FoundPlugin {
  EquationPlugin plugin;
  std::string names;  // TableRecord::names
};
std::optional<FoundPlugin> found_equation_plugin(const std::string& table_text, const std::filesystem::path& cache_dir);

// The headers a model is compiled against, for the library in `libdir`: the build tree's include
// paths (compiled in) when libdir is this build's, else an installed delayspec's LIBDIR/../include,
// which must be root's or this user's and writable by its owner alone (BadInput otherwise).
// `identity`: their names and contents, for the cache key.
struct ModelHeaders {
  std::vector<std::string> include_dirs;
  std::string identity;
};
ModelHeaders model_headers(const std::filesystem::path& libdir);

// Compilations this process has run (tests: a cache hit compiles nothing).
long equation_plugin_compilations();

}  // namespace delayspec::cli
