#pragma once
// Shared output pieces of the commands: multipliers as JSON and as text.
#include <complex>
#include <ostream>
#include <vector>

#include <nlohmann/json.hpp>

namespace delayspec::cli {

// [{"re": .., "im": .., "abs": ..}, ...]
nlohmann::json multipliers_json(const std::vector<std::complex<double>>& values);
// One line per multiplier: index, re, im, |mu|.
void print_multipliers(std::ostream& out, const std::vector<std::complex<double>>& values);

}  // namespace delayspec::cli
