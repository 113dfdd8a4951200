// Where the runner finds swarmbox-netemd for the fault sidecar image (an explicit path, then
// $SWARMBOX_BIN_DIR, the build tree, $PATH) and what it says when it cannot.
#include "swarmbox/runner/fault_image.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace swarmbox::runner {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

TEST(FindNetemd, ExplicitPathMustBeAnExecutableFile) {
  auto ok = FindNetemd("/bin/sh");
  ASSERT_TRUE(ok) << ok.error().ToString();
  EXPECT_EQ(*ok, "/bin/sh");
  auto missing = FindNetemd("/nonexistent/swarmbox-netemd");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code(), ErrorCode::kNotFound);
  EXPECT_EQ(missing.error().where(), "/nonexistent/swarmbox-netemd");
}

TEST(FindNetemd, BinDirComesFirstAndMissingListsWhereItLooked) {
  const fs::path dir = fs::temp_directory_path() / "swarmbox-find-netemd";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path program = dir / "swarmbox-netemd";
  { std::ofstream(program) << "#!/bin/sh\n"; }
  ::chmod(program.c_str(), 0755);
  ::setenv("SWARMBOX_BIN_DIR", dir.c_str(), 1);
  auto found = FindNetemd("");
  ASSERT_TRUE(found) << found.error().ToString();
  EXPECT_EQ(*found, program.string());

  fs::remove(program);
  const char* old_path = std::getenv("PATH");
  const std::string saved = old_path != nullptr ? old_path : "";
  ::setenv("PATH", dir.c_str(), 1);
  auto missing = FindNetemd("");
  ::setenv("PATH", saved.c_str(), 1);
  ::unsetenv("SWARMBOX_BIN_DIR");
  fs::remove_all(dir);
  // (A build tree next to this test binary may hold the real one; then it is found there.)
  if (missing) {
    EXPECT_THAT(*missing, HasSubstr("orchestrator/faults/swarmbox-netemd"));
  } else {
    EXPECT_EQ(missing.error().code(), ErrorCode::kNotFound);
    EXPECT_THAT(missing.error().message(), HasSubstr(program.string()));
    EXPECT_THAT(missing.error().message(), HasSubstr("SWARMBOX_BIN_DIR"));
  }
}

}  // namespace
}  // namespace swarmbox::runner
