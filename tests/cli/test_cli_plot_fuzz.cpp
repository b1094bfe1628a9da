// A fuzz-style test of `delayspec plot` inputs (issue 13): valid result files of every format
// plot reads, mutated (truncated, bytes deleted, inserted or replaced, numbers swapped for nan,
// inf, strings or lists, lines dropped or repeated), with a fixed seed. Every case must end in
// exit 0 (figures), 2 (bad input, with a message) or 3 (gnuplot could not draw it, with a
// message): never an internal error (exit 1), never a crash.
#include <gtest/gtest.h>

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "cli_test_support.hpp"

namespace fs = std::filesystem;

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::run;
using Files = std::vector<std::pair<std::string, std::string>>;  // name -> contents

// Valid inputs, in the formats the commands write (docs/formats.md), small so that a case runs
// gnuplot on a few points only.
const std::vector<Files>& seeds() {
  static const std::vector<Files> all = {
      {{"floquet.json", R"({"model": "linear", "N": 20, "solver": "dense", "multipliers": [
          {"re": 0.5, "im": 0.25, "abs": 0.559}, {"re": -0.1, "im": 0, "abs": 0.1}]})"}},
      {{"chart.csv",
        "# delayspec 0.1.0\n# model = mathieu\n# N = 10\ndelta,b,spectral_radius\n"
        "0,0,0.5\n1,0,1.2\n\n0,1,nan\n1,1,0.9\n"}},
      {{"basin.csv",
        "# model = impact\n# e = 0x1.428f5c28f5c29p+0\n# k = 0.2\nx0,v0,period,max_section_x\n"
        "-3,-3,1,0.9\n3,-3,2,1.7\n\n-3,3,nan,nan\n3,3,0,2.2\n"}},
      {{"exponents.csv",
        "# sweep_key = k\nparameter,lambda1,lambda2,se1,se2,lambda1_per_time,lambda2_per_time,seconds\n"
        "0,0.1,-0.2,0.01,0.01,0.0127,-0.025,1\n0.5,nan,nan,nan,nan,nan,nan,nan\n"
        "1,-0.1,-0.3,0.01,0.02,-0.0127,-0.038,1\n"},
       {"section.csv", "# sweep_key = k\nparameter,x\n0,0.1\n0,0.2\n1,-0.05\n"},
       {"sweep.json", R"({"sweep_key": "k", "sweep_from": 0, "sweep_to": 1})"}},
      {{"trajectory.csv", "t,x,v\n0,0,1\n0.1,0.1,0.99\n0.2,0.2,0.96\n0.3,0.29,0.9\n"},
       {"poincare.csv", "t,x,v\n0,0,1\n0.3,0.29,0.9\n"},
       {"impacts.csv", "t,count\n0.5,1\n9,2\n"},
       {"simulate.json", R"({"metadata": {"parameters": {"e": "1.26", "k": "0.2"}}})"}},
      {{"converge.json", R"({"reference": "exact", "by_events": [
          {"events": "on", "rows": [{"N": 100, "h": 0.01, "error": 1e-3, "seconds": 0.1},
                                    {"N": 200, "h": 0.005, "error": [2.5e-4, 1e-3], "seconds": 0.2}]},
          {"events": "off", "rows": [{"N": 100, "error": 1e-2, "seconds": 0.1}, {"N": 200, "error": null}]}]})"},
       {"bench.json", R"({"rows": [{"N": 100, "solver": "spectra", "seconds": 0.01, "error": 1e-3},
          {"N": 200, "solver": "arpack", "seconds": 0.02, "error": 2e-4}]})"}},
  };
  return all;
}

// Deterministic choices (rng() % n: the same sequence with every standard library).
struct Mutator {
  std::mt19937 rng;
  size_t below(size_t n) { return n == 0 ? 0 : static_cast<size_t>(rng() % n); }

  void mutate(std::string& s) {
    static const char* const tokens[] = {"nan",   "inf",    "-inf",      "-1",        "0",
                                         "1e999", "1e-320", "0x1p-1074", "\"x\"",     "null",
                                         "[]",    "{}",     "true",      "[1,2]",     ",",
                                         "\n",    "\n\n",   "#",         "# e = x\n", "'",
                                         "`",     "\"",     "\\",        "\r\n",      "9999999999999999999999",
                                         "2.5",   ""};
    const size_t at = below(s.size() + 1);
    switch (below(7)) {
      case 0:  // truncate
        s.resize(at);
        break;
      case 1:  // delete a byte
        if (at < s.size()) s.erase(at, 1);
        break;
      case 2:  // insert a random byte
        s.insert(at, 1, static_cast<char>(below(256)));
        break;
      case 3:  // replace a byte
        if (at < s.size()) s[at] = static_cast<char>(below(256));
        break;
      case 4: {  // replace the number (or word) at `at` by a token
        size_t begin = at, end = at;
        auto part = [&](size_t i) {
          return i < s.size() && (std::isalnum(static_cast<unsigned char>(s[i])) || s[i] == '.' || s[i] == '-');
        };
        while (begin > 0 && part(begin - 1)) --begin;
        while (part(end)) ++end;
        s.replace(begin, end - begin, tokens[below(std::size(tokens))]);
        break;
      }
      case 5: {  // drop or repeat a line
        const size_t begin = s.rfind('\n', at == 0 ? 0 : at - 1),
                     line_begin = begin == std::string::npos ? 0 : begin + 1;
        size_t line_end = s.find('\n', line_begin);
        line_end = line_end == std::string::npos ? s.size() : line_end + 1;
        const std::string line = s.substr(line_begin, line_end - line_begin);
        if (below(2)) s.erase(line_begin, line.size());
        else s.insert(line_begin, line);
        break;
      }
      default:  // insert a token
        s.insert(at, tokens[below(std::size(tokens))]);
    }
  }
};

}  // namespace

TEST(PlotFuzz, EveryMutatedInputEndsInExit0_2Or3) {
  const fs::path dir = delayspec::testing::scratch_path("plot_fuzz");
  // DELAYSPEC_PLOT_FUZZ_SEED / _CASES: a longer or different run by hand (the suite: 13, 300).
  const char* seed_text = std::getenv("DELAYSPEC_PLOT_FUZZ_SEED");
  const char* cases_text = std::getenv("DELAYSPEC_PLOT_FUZZ_CASES");
  Mutator m{std::mt19937(seed_text ? static_cast<unsigned>(std::atol(seed_text)) : 13u)};
  const int cases = cases_text ? std::atoi(cases_text) : 300;
  int by_status[4] = {0, 0, 0, 0};
  for (int c = 0; c < cases; ++c) {
    Files files = seeds()[m.below(seeds().size())];
    // One to three mutations, usually of one file of the set, sometimes of two.
    for (size_t k = 0, n = 1 + m.below(3); k < n; ++k) m.mutate(files[m.below(files.size())].second);
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::string trace = "case " + std::to_string(c) + ":";
    for (const auto& [name, text] : files) {
      std::ofstream(dir / name, std::ios::binary) << text;
      trace += "\n--- " + name + "\n" + text;
    }
    SCOPED_TRACE(trace);
    const CliResult r = run({"plot", dir.string(), "--set", "plot_width=100", "--set", "plot_height=100"});
    ASSERT_TRUE(r.status == 0 || r.status == 2 || r.status == 3) << "status " << r.status << ": " << r.err;
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
    if (r.status != 0) {
      EXPECT_FALSE(r.err.empty());
    }
    ++by_status[r.status];
  }
  // The mutations must reach both sides: some inputs still plot, some are rejected. (Not a
  // tuning target: a seed that plotted nothing would test only the readers.)
  EXPECT_GT(by_status[0], cases / 10);
  EXPECT_GT(by_status[2], cases / 10);
  std::printf("plot fuzz: %d cases: %d plotted, %d bad input, %d gnuplot failure\n", cases, by_status[0], by_status[2],
              by_status[3]);
  fs::remove_all(dir);
}
