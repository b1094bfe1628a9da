// A standalone, deterministic driver for the libFuzzer entry points (fuzz_scene.cpp,
// fuzz_equations.cpp), so that they also build with GCC and run in CI as ordinary tests (ctest
// fuzz_scene_fixed, fuzz_equations_fixed; docs/fuzzing.md). libFuzzer itself (clang only) explores
// with coverage feedback for as long as it is given; this driver runs a fixed, reproducible set:
//   1. every seed file of the corpus directory (sorted by name), as it is;
//   2. COUNT mutants of the seeds, 1 to 4 edits each: bit flips and byte replacements (ASCII
//      mostly), insertions of tokens that matter to the parsers (`(`, `sin(`, `^`, `[equations]`,
//      `1e308`, quotes, brackets, ...) anywhere and of expression tokens inside strings (where
//      the expressions of an [equations] table are), deletions, duplications and splices of two
//      seeds. The i-th mutant depends only on the seeds and i (its own generator, a fixed formula,
//      no std:: distributions, whose results differ between standard libraries).
// Mutants are at most max_length bytes (2 KB): the known stack overflow of GiNaC's parser on
// thousands of nested parentheses (issue 31, fixed by the depth limit of
// src/modules/equations/equation_expression.cpp) is not what a fixed CI run should keep finding.
//
// Usage: DRIVER CORPUS_DIR COUNT     the run above; exit 0, or 1 after an escaped exception
//        DRIVER CORPUS_DIR COUNT I    writes mutant I (0-based) to stdout, for replay
//        DRIVER FILE                  runs one input (a crash file, a mutant written as above)
// A crash (signal, sanitizer report) ends the process: rerun with DELAYSPEC_FUZZ_TRACE=1, which
// prints each mutant's index to stderr before it runs, then extract that mutant with the second form.
#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

namespace fs = std::filesystem;

constexpr size_t max_length = 2048;

// Tokens of TOML, of the scene keys and of the [equations] grammar (docs/models.md).
const std::vector<std::string>& tokens() {
  static const std::vector<std::string> list = {
      "(", ")", "sin(", "cos(", "exp(", "log(", "sqrt(", "atan(", "^", "*", "/", "+", "-", "x_tau", "t", "pi",
      "[equations]", "\n[equations]\n", "state", "parameters", "period", "delay", "rhs", "rhs_switched", "switch",
      "history", "model = \"equations\"", "1e308", "-1e308", "1e-308", "0", "-0", "1/0", "0/0", "nan", "inf", "99999999999999999999",
      "18446744073709551616", "\"", "'", "\"\"\"", "'''", "[", "]", "{", "}", "[[", "]]", ",", "=", ".", "#", "\\",
      "\\u00e9", "\n", " ", "\t", "\r\n", "\xc2\xa1", "\xef\xbb\xbf", "true", "x", "v", "N", "tau", "nev", "a__b",
      "int", "and", "_tau", "2^-1", "x*-y", "a^b^c", "((((((((", "))))))))"};
  return list;
}

// splitmix64: the mutant's generator (a fixed formula: the same numbers with every compiler).
struct Random {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  size_t below(size_t n) { return n == 0 ? 0 : static_cast<size_t>(next() % n); }
};

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::vector<std::string> read_corpus(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  std::vector<std::string> seeds;
  for (const auto& f : files) seeds.push_back(read_file(f));
  return seeds;
}

// The contents of the basic strings of a TOML text ("..." on one line), as [begin, end) offsets:
// where expressions live, so that edits there reach the expression reader, not only TOML's.
std::vector<std::pair<size_t, size_t>> string_contents(const std::string& s) {
  std::vector<std::pair<size_t, size_t>> ranges;
  size_t open = std::string::npos;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\n') open = std::string::npos;
    else if (s[i] == '\\' && open != std::string::npos) ++i;  // an escape: skip the next byte
    else if (s[i] == '"' && open == std::string::npos) open = i + 1;
    else if (s[i] == '"') {
      ranges.push_back({open, i});
      open = std::string::npos;
    }
  }
  return ranges;
}

// Tokens of the expression grammar (docs/models.md), for insertion inside strings.
const std::vector<std::string>& expression_tokens() {
  static const std::vector<std::string> list = {
      "(", ")", "sin(", "cos(", "tan(", "exp(", "log(", "sqrt(", "asin(", "acosh(", "abs(", "^", "^(", "*", "/", "+",
      "-", "x", "v", "x_tau", "v_tau", "t", "pi", "I", "e", "k", "omega", "1e308", "1e-308", "0", "0.1", ".5", "2^-1",
      "1/0", "0^0", "log(0)", "sqrt(-1)", "x*-y", "a^b^c", "99999999999999999999", "1e309", ",", " ", "__", "_tau",
      "int", "((", "))", "sin(sin(", "x^x", "t*x", "exp(exp(exp(", "^1e308", "2^1000"};
  return list;
}

// An ASCII byte most of the time (non-ASCII outside strings is refused at once, which would stop
// most mutants at the first check), any byte sometimes.
char some_byte(Random& random) {
  if (random.below(16) == 0) return static_cast<char>(random.below(256));
  const size_t k = random.below(96);
  return k == 95 ? '\n' : static_cast<char>(0x20 + k);
}

// Mutant `index` of the seeds: one seed, 1 to 4 edits.
std::string mutant(const std::vector<std::string>& seeds, std::uint64_t index) {
  Random random{0x64656c6179737063ull ^ (index * 0x2545f4914f6cdd1dull)};
  std::string s = seeds[random.below(seeds.size())];
  const size_t edits = 1 + random.below(4);
  for (size_t e = 0; e < edits; ++e) {
    const size_t at = random.below(s.size() + 1);
    switch (random.below(12)) {
      case 0:  // flip one bit (of the low seven mostly: see some_byte)
        if (!s.empty()) s[std::min(at, s.size() - 1)] ^= static_cast<char>(1u << random.below(random.below(16) ? 7 : 8));
        break;
      case 1:  // replace one byte
        if (!s.empty()) s[std::min(at, s.size() - 1)] = some_byte(random);
        break;
      case 2: {  // insert a token anywhere
        const std::string& token = tokens()[random.below(tokens().size())];
        s.insert(at, token);
        break;
      }
      case 3:
      case 4:
      case 5:
      case 6:
      case 7: {  // insert an expression token inside a string (5 in 12: most edits of raw bytes
                 // end at TOML's parser, and the expressions' reader is the deeper one)
        const auto ranges = string_contents(s);
        if (ranges.empty()) break;
        const auto [begin, end] = ranges[random.below(ranges.size())];
        s.insert(begin + random.below(end - begin + 1), expression_tokens()[random.below(expression_tokens().size())]);
        break;
      }
      case 8: {  // delete a few bytes inside a string
        const auto ranges = string_contents(s);
        if (ranges.empty()) break;
        const auto [begin, end] = ranges[random.below(ranges.size())];
        const size_t from = begin + random.below(end - begin + 1);
        s.erase(from, std::min(end - from, 1 + random.below(4)));
        break;
      }
      case 9:  // delete up to 16 bytes
        s.erase(at, 1 + random.below(16));
        break;
      case 10: {  // duplicate a range (repeats: nested calls, repeated keys)
        const size_t from = random.below(s.size() + 1);
        const std::string piece = s.substr(from, 1 + random.below(64));
        s.insert(at, piece);
        break;
      }
      default: {  // splice: the head of this input, the tail of another seed
        const std::string& other = seeds[random.below(seeds.size())];
        s = s.substr(0, at) + other.substr(random.below(other.size() + 1));
        break;
      }
    }
    if (s.size() > max_length) s.resize(max_length);
  }
  return s;
}

// One input through the entry point; false (with the input, escaped, on stderr) if an exception
// escaped it. The entry points catch BadInput themselves: anything else is a finding.
bool run_one(const std::string& input, const std::string& label) {
  try {
    LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(input.data()), input.size());
    return true;
  } catch (const std::exception& e) {
    std::cerr << "FINDING: " << label << ": " << e.what() << "\ninput (" << input.size() << " bytes): \"";
  } catch (...) {
    std::cerr << "FINDING: " << label << ": an exception of unknown type\ninput (" << input.size() << " bytes): \"";
  }
  for (unsigned char c : input) {
    if (c == '\\' || c == '"') std::cerr << '\\' << c;
    else if (c >= 0x20 && c < 0x7f) std::cerr << c;
    else if (c == '\n') std::cerr << "\\n";
    else {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      std::cerr << hex;
    }
  }
  std::cerr << "\"\n";
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && fs::is_regular_file(argv[1])) return run_one(read_file(argv[1]), argv[1]) ? 0 : 1;
  if (argc != 3 && argc != 4) {
    std::cerr << "usage: " << argv[0] << " CORPUS_DIR COUNT [INDEX] | " << argv[0] << " FILE\n";
    return 2;
  }
  const std::vector<std::string> seeds = read_corpus(argv[1]);
  const long count = std::atol(argv[2]);
  if (seeds.empty() || count < 0) {
    std::cerr << argv[0] << ": no seed files in `" << argv[1] << "`, or COUNT < 0\n";
    return 2;
  }
  if (argc == 4) {
    std::cout << mutant(seeds, std::strtoull(argv[3], nullptr, 10));
    return 0;
  }
  const bool trace = std::getenv("DELAYSPEC_FUZZ_TRACE") != nullptr;
  long findings = 0;
  for (size_t i = 0; i < seeds.size(); ++i) findings += !run_one(seeds[i], "seed " + std::to_string(i));
  for (long i = 0; i < count; ++i) {
    const std::string input = mutant(seeds, static_cast<std::uint64_t>(i));
    if (trace) std::cerr << "mutant " << i << "\n";
    findings += !run_one(input, "mutant " + std::to_string(i));
  }
  std::cout << argv[0] << ": " << seeds.size() << " seeds and " << count << " mutants, " << findings
            << " finding(s)\n";
  return findings == 0 ? 0 : 1;
}
