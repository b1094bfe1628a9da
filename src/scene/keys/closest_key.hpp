#pragma once
// The did-you-mean of every message about an unknown name: a key (Config, key_registry.hpp), an
// analysis of `run`, a name in a scene's [equations] (src/modules/equations). A pure function of its
// arguments, so the equations module (libdelayspec_equations, which does not link the CLI
// library) compiles this file into itself too.
#include <string>
#include <vector>

namespace delayspec::cli {

// The closest candidate to `key` (edit distance, case-insensitive; keys of 1-2 characters only
// by case, 3-4 characters at most 1 edit, longer at most 2), or "" if none.
std::string closest_key(const std::string& key, const std::vector<std::string>& candidates);

}  // namespace delayspec::cli
