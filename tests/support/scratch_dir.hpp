#pragma once
// The tests' scratch files: all under one folder per test process, TMP/delayspec_test_PID
// (ctest runs each case in a process of its own, several at once), which the process removes as it
// ends when every test it ran passed. A failing test's files stay for a look.
#include <filesystem>
#include <string>
#include <system_error>

#include <unistd.h>

#include <gtest/gtest.h>

namespace delayspec::testing {

// The process's scratch folder, created on first use.
inline const std::filesystem::path& scratch_root() {
  struct Root {
    pid_t owner = ::getpid();
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("delayspec_test_" + std::to_string(::getpid()));
    Root() { std::filesystem::create_directories(path); }
    ~Root() {
      // Only the process that made it (a forked child that returns through exit() runs this too),
      // and only after a clean run. GoogleTest's UnitTest is never destroyed, so it can be asked here.
      if (::getpid() != owner || !::testing::UnitTest::GetInstance()->Passed()) return;
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Root root;
  return root.path;
}

// NAME (a file or folder name) in the scratch folder, removed first and not created.
inline std::filesystem::path scratch_path(const std::string& name) {
  const std::filesystem::path path = scratch_root() / name;
  std::filesystem::remove_all(path);
  return path;
}

}  // namespace delayspec::testing
