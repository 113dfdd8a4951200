// images::FindProgram: an explicit path, then $SWARMBOX_BIN_DIR, the caller's preferred places, the
// running program's own folder (an installed <prefix>/bin) and $PATH, in that order; a miss names
// every place looked in and the caller's hint.
#include "swarmbox/images/find_program.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace swarmbox::images {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// Three directories each holding an executable `swarmbox-x`; the environment restored afterwards.
class FindProgramTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("swarmbox-find-program-" + std::to_string(::getpid()));
    fs::remove_all(root_);
    for (const char* d : {"bin", "preferred", "path"}) {
      fs::create_directories(root_ / d);
      const fs::path p = root_ / d / "swarmbox-x";
      { std::ofstream(p) << "#!/bin/sh\n"; }
      ::chmod(p.c_str(), 0755);
    }
    const char* path = std::getenv("PATH");
    saved_path_ = path != nullptr ? path : "";
    ::setenv("PATH", (root_ / "path").c_str(), 1);
    ::setenv("SWARMBOX_BIN_DIR", (root_ / "bin").c_str(), 1);
  }
  void TearDown() override {
    ::setenv("PATH", saved_path_.c_str(), 1);
    ::unsetenv("SWARMBOX_BIN_DIR");
    fs::remove_all(root_);
  }
  Result<std::string> Find(const std::string& explicit_path = "") const {
    return FindProgram("swarmbox-x", explicit_path, {root_ / "preferred" / "swarmbox-x"}, "build it");
  }

  fs::path root_;
  std::string saved_path_;
};

TEST_F(FindProgramTest, BinDirThenPreferredThenPath) {
  auto found = Find();
  ASSERT_TRUE(found) << found.error().ToString();
  EXPECT_EQ(*found, (root_ / "bin" / "swarmbox-x").string());
  fs::remove(root_ / "bin" / "swarmbox-x");
  found = Find();
  ASSERT_TRUE(found) << found.error().ToString();
  EXPECT_EQ(*found, (root_ / "preferred" / "swarmbox-x").string());
  fs::remove(root_ / "preferred" / "swarmbox-x");
  found = Find();
  ASSERT_TRUE(found) << found.error().ToString();
  EXPECT_EQ(*found, (root_ / "path" / "swarmbox-x").string());
}

// An installed swarmbox finds swarmbox-physics beside it in <prefix>/bin: the test program's own
// folder plays <prefix>/bin here, holding a companion that is also on $PATH.
TEST_F(FindProgramTest, NextToTheRunningProgramAfterPreferredBeforePath) {
  const std::string name = "swarmbox-find-program-companion-" + std::to_string(::getpid());
  const fs::path beside = SelfDir() / name;
  ASSERT_FALSE(SelfDir().empty());
  { std::ofstream(beside) << "#!/bin/sh\n"; }
  ::chmod(beside.c_str(), 0755);
  { std::ofstream(root_ / "path" / name) << "#!/bin/sh\n"; }
  ::chmod((root_ / "path" / name).c_str(), 0755);
  auto found = FindProgram(name, "", {root_ / "preferred" / name}, "build it");
  fs::remove(beside);
  ASSERT_TRUE(found) << found.error().ToString();
  EXPECT_EQ(*found, beside.lexically_normal().string());
  found = FindProgram(name, "", {root_ / "preferred" / name}, "build it");
  ASSERT_TRUE(found) << found.error().ToString();
  EXPECT_EQ(*found, (root_ / "path" / name).string());
}

TEST_F(FindProgramTest, ANonExecutableFileIsNotAProgram) {
  ::chmod((root_ / "bin" / "swarmbox-x").c_str(), 0644);
  auto found = Find();
  ASSERT_TRUE(found) << found.error().ToString();
  EXPECT_EQ(*found, (root_ / "preferred" / "swarmbox-x").string());
}

TEST_F(FindProgramTest, MissEverywhereNamesEachPlaceAndTheHint) {
  for (const char* d : {"bin", "preferred", "path"}) fs::remove(root_ / d / "swarmbox-x");
  auto missing = Find();
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code(), ErrorCode::kNotFound);
  for (const char* d : {"bin", "preferred", "path"}) {
    EXPECT_THAT(missing.error().message(), HasSubstr((root_ / d / "swarmbox-x").string()));
  }
  EXPECT_THAT(missing.error().message(), HasSubstr((SelfDir() / "swarmbox-x").string()));
  EXPECT_THAT(missing.error().message(), HasSubstr("cannot find swarmbox-x"));
  EXPECT_THAT(missing.error().message(), HasSubstr("; build it"));
}

TEST_F(FindProgramTest, AnExplicitPathWinsOrFailsWithoutSearching) {
  auto found = Find((root_ / "path" / "swarmbox-x").string());
  ASSERT_TRUE(found) << found.error().ToString();
  EXPECT_EQ(*found, (root_ / "path" / "swarmbox-x").string());
  auto missing = Find((root_ / "nothing-here").string());
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code(), ErrorCode::kNotFound);
  EXPECT_EQ(missing.error().where(), (root_ / "nothing-here").string());
  EXPECT_THAT(missing.error().message(), HasSubstr("swarmbox-x: not an executable file"));
}

}  // namespace
}  // namespace swarmbox::images
