// Atomic output files: the target appears complete or not at all; no temporary is left behind
// after success or a failed write.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "scene/output/atomic_file.hpp"
#include "delayspec/errors.hpp"
#include "scratch_dir.hpp"
#include "text_support.hpp"

namespace fs = std::filesystem;
using delayspec::cli::AtomicFile;
using delayspec::cli::write_file_atomically;
using delayspec::testing::read_text;

namespace {

fs::path atomic_scratch_dir(const std::string& name) {
  return delayspec::testing::scratch_path("atomic_" + name);
}

size_t entries(const fs::path& dir) {
  size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

}  // namespace

TEST(AtomicFile, WritesCreatesDirectoryAndReplaces) {
  const fs::path dir = atomic_scratch_dir("write");
  write_file_atomically(dir / "sub" / "a.csv", "x,y\n1,2\n");
  EXPECT_EQ(read_text(dir / "sub" / "a.csv"), "x,y\n1,2\n");
  write_file_atomically(dir / "sub" / "a.csv", "new\n");
  EXPECT_EQ(read_text(dir / "sub" / "a.csv"), "new\n");
  EXPECT_EQ(entries(dir / "sub"), 1u) << "no temporary left behind";
}

TEST(AtomicFile, UncommittedFileNeverAppears) {
  const fs::path dir = atomic_scratch_dir("uncommitted");
  fs::create_directories(dir);
  {
    AtomicFile f(dir / "result.json");
    f.stream() << "{\"partial\": ";
  }  // destroyed without commit(): an interrupted run
  EXPECT_FALSE(fs::exists(dir / "result.json"));
  EXPECT_EQ(entries(dir), 0u);
  AtomicFile g(dir / "result.json");
  g.stream() << "{}\n";
  g.commit();
  g.commit();
  EXPECT_EQ(read_text(dir / "result.json"), "{}\n");
}

TEST(AtomicFile, UnwritableLocationIsBadInputNamingThePath) {
  const fs::path dir = atomic_scratch_dir("blocked");
  fs::create_directories(dir);
  std::ofstream(dir / "file") << "x";  // a regular file where a directory is wanted
  try {
    write_file_atomically(dir / "file" / "out.csv", "x\n");
    FAIL() << "expected BadInput";
  } catch (const delayspec::BadInput& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "file" / "out.csv").string()), std::string::npos) << e.what();
  }
  EXPECT_EQ(read_text(dir / "file"), "x");
}
