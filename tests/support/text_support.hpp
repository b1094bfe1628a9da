#pragma once
// Reading back what a test wrote: a file's bytes, a CSV's table without its metadata, a substring.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

namespace delayspec::testing {

inline bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The file's bytes (empty when it cannot be opened).
inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A CSV's table without its "# ..." metadata lines.
inline std::string without_metadata(const std::string& csv) {
  std::string out, line;
  std::stringstream ss(csv);
  while (std::getline(ss, line))
    if (line.rfind('#', 0) != 0) out += line + "\n";
  return out;
}

}  // namespace delayspec::testing
