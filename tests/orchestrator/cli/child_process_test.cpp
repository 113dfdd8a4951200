// ChildProcess: exit codes, signals, deadlines and output files, with small system programs.
#include "child_process.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <csignal>
#include <filesystem>

namespace swarmbox::cli::testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

class ChildProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("swarmbox-child-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(ChildProcessTest, ReportsTheExitCodeAndWhatWasPrinted) {
  auto done = RunToEnd({"/bin/ls", "-d", "/", "/no/such/dir"}, 10s, dir_.string());
  ASSERT_TRUE(done) << done.error().ToString();
  EXPECT_EQ(done->code, 2);  // ls: a missing operand is a "serious trouble" exit
  EXPECT_EQ(done->out, "/\n");
  EXPECT_THAT(done->err, ::testing::HasSubstr("/no/such/dir"));
  // The scratch files are gone.
  EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(ChildProcessTest, ArgumentsAreNotInterpretedByAShell) {
  auto done = RunToEnd({"/bin/echo", "$HOME;", "`id`", "a  b"}, 10s, dir_.string());
  ASSERT_TRUE(done) << done.error().ToString();
  EXPECT_EQ(done->out, "$HOME; `id` a  b\n");
}

TEST_F(ChildProcessTest, ASignalEndsItWith128PlusTheSignal) {
  auto child = ChildProcess::Spawn({"/bin/sleep", "30"}, "", "");
  ASSERT_TRUE(child) << child.error().ToString();
  EXPECT_EQ(child->Wait(50ms), std::nullopt);  // still running
  EXPECT_TRUE(child->running());
  ASSERT_TRUE(child->Signal(SIGINT));  // default action in the child, whatever this process set
  EXPECT_EQ(child->Wait(10s), std::optional<int>(128 + SIGINT));
  EXPECT_FALSE(child->running());
  EXPECT_FALSE(child->Signal(SIGKILL));  // reaped: nothing to signal
}

TEST_F(ChildProcessTest, RunToEndKillsAProgramPastItsDeadline) {
  auto done = RunToEnd({"/bin/sleep", "30"}, 100ms, dir_.string());
  ASSERT_FALSE(done);
  EXPECT_EQ(done.error().code(), ErrorCode::kTimeout);
  EXPECT_THAT(done.error().message(), ::testing::HasSubstr("did not end within 100 ms"));
}

TEST_F(ChildProcessTest, AMissingProgramIsAnError) {
  auto child = ChildProcess::Spawn({"/no/such/program"}, "", "");
  // glibc reports exec failures of posix_spawn as its result (ENOENT).
  ASSERT_FALSE(child);
  EXPECT_EQ(child.error().where(), "/no/such/program");
  EXPECT_FALSE(ChildProcess::Spawn({}, "", ""));
}

TEST_F(ChildProcessTest, DestroyingARunningChildKillsAndReapsIt) {
  pid_t pid = 0;
  {
    auto child = ChildProcess::Spawn({"/bin/sleep", "30"}, "", "");
    ASSERT_TRUE(child);
    pid = child->pid();
  }
  // Reaped: the pid no longer names a process of ours (not even a zombie).
  EXPECT_NE(::kill(pid, 0), 0);
}

}  // namespace
}  // namespace swarmbox::cli::testing
