// libFuzzer target for the scene parser: arbitrary bytes as a scene file, then everything a
// command does with a scene before computing (flatten, typed getters, the problem and orbit
// keys, the grid, the unknown-key check). Bad input must end in BadInput; anything else (another
// exception, a crash, a sanitizer report, a hang) is a finding.
// A scene with model = equations stops before read_problem, which would compile its model: its
// [equations] table is fuzz_equations.cpp's.
// With libFuzzer (clang, DELAYSPEC_FUZZ):
//     CXX=clang++ CC=clang cmake -S . -B build-fuzz -G Ninja -DDELAYSPEC_FUZZ=ON
//         -DDELAYSPEC_BUILD_TESTS=OFF -DDELAYSPEC_BUILD_BENCH=OFF     (one line)
//     ninja -C build-fuzz fuzz_scene
//     build-fuzz/fuzz_scene -max_total_time=60 -max_len=512 tests/fuzz_corpus
// and in every test build with the standalone driver tests/fuzz_driver.cpp, as the test
// fuzz_scene_fixed (a fixed set of mutants of tests/fuzz_corpus/). docs/fuzzing.md.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "scene/keys/config.hpp"
#include "delayspec/errors.hpp"
#include "scene/problem/orbit_settings.hpp"
#include "scene/problem/problem.hpp"
#include "scene/commands/key_registry.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    delayspec::cli::Config config = delayspec::cli::Config::from_scene_text(text, "fuzz.toml");
    config.set_key_index(&delayspec::cli::key_index);  // as run_command gives it
    // Every key the scene gives, through every typed getter (each must throw BadInput or succeed).
    for (const auto& [key, value] : config.values()) {  // the getters below work on copies
      for (int getter = 0; getter < 4; ++getter) {
        delayspec::cli::Config copy = config;
        try {
          if (getter == 0) copy.get_double(key, 0);
          if (getter == 1) copy.get_int(key, 0);
          if (getter == 2) copy.get_int_list(key, {});
          if (getter == 3) copy.get_choice(key, "on", {"on", "off"});
        } catch (const delayspec::BadInput&) {
        }
      }
    }
    if (config.values().count("model") && config.values().at("model") == "equations") return 0;  // (above)
    delayspec::cli::Problem problem = delayspec::cli::read_problem(config, 100);
    delayspec::cli::read_orbit_settings(config);
    config.get_string("analyses", "");
    config.check_all_used();
  } catch (const delayspec::BadInput& e) {
    if (std::getenv("DELAYSPEC_FUZZ_SHOW")) std::fprintf(stderr, "BadInput: %s\n", e.what());  // seeds' check
  }
  return 0;
}
