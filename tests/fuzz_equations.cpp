// libFuzzer target for the [equations] reader of model = equations: arbitrary bytes as a scene
// file, then what the program does with its [equations] table before it compiles anything
// (src/scene/equations/equation_model.cpp, load): the table as the text Config keeps, parsed again by toml++,
// then the equations module's generate_equation_model (equation_model_source.hpp): the entries,
// names and expressions checked, parsed and differentiated by GiNaC, the switch rules, and the
// model printed as C++. The C++ is never compiled here (no compiler call, no cache): that is the
// plugin loader's part. Bad input must end in BadInput; anything else (another exception, a
// crash, a sanitizer report, a hang) is a finding.
// Built as a libFuzzer target in a DELAYSPEC_FUZZ build (clang), and with the standalone driver
// tests/fuzz_driver.cpp as the test fuzz_equations_fixed (seeds: tests/fuzz_corpus_equations/).
// docs/fuzzing.md.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "scene/keys/config.hpp"
#include "delayspec/errors.hpp"
#include "scene/equations/equation_model.hpp"  // engine_keys
#include "scene/equations/equations_module_loader.hpp"
#include "scene/commands/key_registry.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    delayspec::cli::Config config = delayspec::cli::Config::from_scene_text(text, "fuzz.toml");
    if (!config.has("equations")) return 0;
    const std::string table_text = config.get_string("equations", "");
    // As equation_model.cpp reads it: a table Config printed must parse again; in the program a
    // failure here is BadInput naming `equations`.
    toml::table table;
    try {
      table = toml::parse(std::string_view(table_text), std::string_view("[equations]"));
    } catch (const toml::parse_error& e) {
      throw delayspec::BadInput("`equations`: " + std::string(e.description()));
    }
    static const std::vector<std::string> reserved = delayspec::cli::engine_keys(delayspec::cli::key_index());
    const delayspec::cli::EquationModelSource source = delayspec::cli::equations_module().generate(table, reserved);
    // The source is C++ text of one struct, never empty for a table that passed the checks.
    if (source.code.empty() || source.state.empty()) throw std::logic_error("generate_equation_model: empty model");
  } catch (const delayspec::BadInput& e) {
    if (std::getenv("DELAYSPEC_FUZZ_SHOW")) std::fprintf(stderr, "BadInput: %s\n", e.what());  // seeds' check
  }
  return 0;
}
