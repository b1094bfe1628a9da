#pragma once
// The delayspec command line run in-process (run_cli, as main() does), for the CLI tests:
// exit status and everything written to stdout and stderr.
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "cli/run_cli.hpp"
#include "scratch_dir.hpp"
#include "text_support.hpp"

namespace delayspec::testing {

struct CliResult {
  int status;
  std::string out, err;
};

// A scratch folder for one test, removed first and not created (scratch_dir.hpp).
inline std::filesystem::path fresh_dir(const std::string& name) { return scratch_path(name); }

// `args` without the program name, e.g. {"floquet", scene, "--json", "--set", "N=40"}.
inline CliResult run(std::vector<std::string> args) {
  args.insert(args.begin(), "delayspec");
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  const int status = delayspec::cli::run_cli(static_cast<int>(argv.size()), argv.data(), out, err);
  return {status, out.str(), err.str()};
}

// `head` followed by --set S for each S of `sets`.
inline std::vector<std::string> with_sets(std::vector<std::string> head, const std::vector<std::string>& sets) {
  for (const auto& s : sets) {
    head.push_back("--set");
    head.push_back(s);
  }
  return head;
}

// One bad-input case of a parameterised test: `COMMAND --set KEY=VALUE` must exit 2 with
// `expected` in its message.
struct BadKey {
  const char* command;
  const char* key;
  const char* value;
  const char* expected;
};
inline void PrintTo(const BadKey& b, std::ostream* os) { *os << b.command << ":" << b.key << "=" << b.value; }

// `COMMAND --set base... --set KEY=VALUE` of the case exits 2, `expected` in the message, nothing
// on stdout.
inline void expect_bad_input(const BadKey& b, const std::vector<std::string>& base) {
  std::vector<std::string> sets = base;
  sets.push_back(std::string(b.key) + "=" + b.value);
  const CliResult r = run(with_sets({b.command}, sets));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(contains(r.err, b.expected)) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

}  // namespace delayspec::testing
