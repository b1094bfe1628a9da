#include "output.hpp"

#include <cstdio>

namespace delayspec::cli {

nlohmann::json multipliers_json(const std::vector<std::complex<double>>& values) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& mu : values) list.push_back({{"re", mu.real()}, {"im", mu.imag()}, {"abs", std::abs(mu)}});
  return list;
}

void print_multipliers(std::ostream& out, const std::vector<std::complex<double>>& values) {
  char line[160];
  std::snprintf(line, sizeof line, "  %3s  %22s  %22s  %18s\n", "#", "re", "im", "|mu|");
  out << line;
  for (size_t i = 0; i < values.size(); ++i) {
    std::snprintf(line, sizeof line, "  %3zu  %22.15e  %22.15e  %18.15f\n", i + 1, values[i].real(),
                  values[i].imag(), std::abs(values[i]));
    out << line;
  }
}

}  // namespace delayspec::cli
