// ChildProcess and LoggedChild: exit codes, signals, deadlines, output files, stdin, and no
// process left behind, with small system programs.
#include "support/child_process.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "support/files.hpp"
#include "support/logged_child.hpp"

namespace swarmbox::testing {
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

TEST_F(ChildProcessTest, RunsInTheGivenWorkingDirectory) {
  fs::create_directories(dir_ / "work");
  SpawnOptions options;
  options.stdout_path = (dir_ / "out.txt").string();  // opened before the child changes directory
  options.working_dir = (dir_ / "work").string();
  auto child = ChildProcess::Spawn({"/bin/pwd", "-P"}, options);
  ASSERT_TRUE(child) << child.error().ToString();
  EXPECT_EQ(child->Wait(10s), std::optional<int>(0));
  EXPECT_EQ(ReadWholeFile((dir_ / "out.txt").string()), fs::canonical(dir_ / "work").string() + "\n");

  options.working_dir = (dir_ / "missing").string();  // a directory that is not there: the spawn fails
  EXPECT_FALSE(ChildProcess::Spawn({"/bin/pwd"}, options));
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

// A process that is gone, or a zombie waiting for init to reap it: it runs no more.
bool Ended(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return true;
  const auto paren = line.rfind(')');
  return paren != std::string::npos && line.size() > paren + 2 && line[paren + 2] == 'Z';
}

TEST_F(ChildProcessTest, DestroyingARunningChildKillsWhatItStartedToo) {
  const std::string out = (dir_ / "grandchild.pid").string();
  pid_t grandchild = 0;
  {
    auto child = ChildProcess::Spawn({"/bin/sh", "-c", "sleep 30 & echo $!; wait"}, out, "");
    ASSERT_TRUE(child) << child.error().ToString();
    for (int i = 0; i < 1000 && grandchild == 0; ++i) {  // until sh has printed the pid
      const std::string text = ReadWholeFile(out);
      if (!text.empty() && text.back() == '\n') grandchild = static_cast<pid_t>(std::stol(text));
      std::this_thread::sleep_for(10ms);
    }
    ASSERT_GT(grandchild, 0);
    EXPECT_FALSE(Ended(grandchild));
  }
  // The whole process group got SIGKILL: the orphaned sleep ends too (init reaps it later).
  for (int i = 0; i < 500 && !Ended(grandchild); ++i) std::this_thread::sleep_for(10ms);
  EXPECT_TRUE(Ended(grandchild));
}

TEST_F(ChildProcessTest, StopEndsItWithSigtermOrSigkillAfterTheGrace) {
  auto polite = ChildProcess::Spawn({"/bin/sleep", "30"}, "", "");
  ASSERT_TRUE(polite);
  EXPECT_EQ(polite->Stop(5s), 128 + SIGTERM);
  EXPECT_EQ(polite->Stop(5s), 128 + SIGTERM);  // idempotent
  EXPECT_FALSE(polite->running());
  // A program that ignores SIGTERM is SIGKILLed once the grace has passed.
  const std::string ready = (dir_ / "ready").string();
  auto stubborn = ChildProcess::Spawn(
      {"/bin/sh", "-c", "trap '' TERM; echo ready; while :; do sleep 1; done"}, ready, "");
  ASSERT_TRUE(stubborn);
  for (int i = 0; i < 1000 && ReadWholeFile(ready).empty(); ++i) std::this_thread::sleep_for(10ms);
  EXPECT_EQ(stubborn->Stop(200ms), 128 + SIGKILL);
}

TEST_F(ChildProcessTest, StdinIsEmptyAndOneFileCanTakeBothStreams) {
  const std::string both = (dir_ / "both.log").string();
  auto child = ChildProcess::Spawn({"/bin/sh", "-c", "cat; echo out; echo err >&2; echo out2"},
                                   SpawnOptions{.stdout_path = both, .stderr_path = both});
  ASSERT_TRUE(child) << child.error().ToString();
  EXPECT_EQ(child->Wait(10s), std::optional<int>(0));  // cat read /dev/null: no wait for input
  EXPECT_EQ(ReadWholeFile(both), "out\nerr\nout2\n");  // in order, nothing overwritten
}

TEST_F(ChildProcessTest, AMovedChildIsOwnedByItsNewObjectOnly) {
  auto child = ChildProcess::Spawn({"/bin/sleep", "30"}, "", "");
  ASSERT_TRUE(child);
  ChildProcess moved = std::move(*child);
  EXPECT_FALSE(child->running());  // NOLINT(bugprone-use-after-move): the moved-from state is defined
  EXPECT_FALSE(child->Signal(SIGTERM));
  EXPECT_EQ(child->Stop(1s), -1);
  EXPECT_TRUE(moved.running());
  EXPECT_TRUE(moved.Signal(SIGKILL));
  EXPECT_EQ(moved.Wait(10s), std::optional<int>(128 + SIGKILL));
}

TEST_F(ChildProcessTest, SelfExecutableNamesThisTestProgram) {
  const std::string self = SelfExecutable();
  EXPECT_TRUE(fs::path(self).is_absolute()) << self;
  EXPECT_EQ(fs::path(self).filename(), "test_support_test");  // the target in CMakeLists.txt
}

TEST_F(ChildProcessTest, LoggedChildWritesBothStreamsToItsLog) {
  const std::string log = (dir_ / "logged.log").string();
  LoggedChild child({"/bin/sh", "-c", "echo hello; echo oops >&2; exit 3"}, log);
  ASSERT_GT(child.pid(), 0) << child.spawn_error();
  EXPECT_EQ(child.Wait(10s), 3);
  EXPECT_FALSE(child.running());
  EXPECT_EQ(child.ReadLog(), "hello\noops\n");
  EXPECT_EQ(child.log_path(), log);
}

TEST_F(ChildProcessTest, LoggedChildWaitIsMinusOneWhileItRunsAndAfterAFailedSpawn) {
  LoggedChild sleeper({"/bin/sleep", "30"}, (dir_ / "sleep.log").string());
  EXPECT_EQ(sleeper.Wait(20ms), -1);
  EXPECT_TRUE(sleeper.running());
  sleeper.Terminate();
  EXPECT_EQ(sleeper.Wait(10s), 128 + SIGTERM);

  LoggedChild missing({"/no/such/program"}, (dir_ / "missing.log").string());
  EXPECT_EQ(missing.pid(), -1);
  EXPECT_FALSE(missing.running());
  EXPECT_EQ(missing.Wait(10ms), -1);
  EXPECT_THAT(missing.spawn_error(), ::testing::HasSubstr("/no/such/program"));
}

TEST_F(ChildProcessTest, LoggedChildWaitsForALineOfItsLog) {
  LoggedChild server({"/bin/sh", "-c", "echo starting; sleep 0.2; echo event=ready; sleep 30"},
                     (dir_ / "server.log").string());
  ASSERT_TRUE(server.WaitForLog("event=ready", 10s)) << server.ReadLog();
  EXPECT_FALSE(server.WaitForLog("event=never", 50ms));  // still running: the timeout ends the wait
  EXPECT_TRUE(server.Terminate());
  EXPECT_EQ(server.Wait(10s), 128 + SIGTERM);
  EXPECT_FALSE(server.Terminate());  // reaped: nothing to signal

  // A program that ends without the line: the wait ends with it, not at the timeout.
  LoggedChild quitter({"/bin/sh", "-c", "echo bye; exit 4"}, (dir_ / "quitter.log").string());
  EXPECT_FALSE(quitter.WaitForLog("event=ready", std::chrono::minutes(10)));
  EXPECT_EQ(quitter.Wait(0ms), 4);
  EXPECT_TRUE(quitter.WaitForLog("bye", 0ms));  // what it printed is still there
}

TEST(MakeTempDir, MakesAFreshEmptyDirectoryEachTime) {
  const std::string a = MakeTempDir("swarmbox_support_test_");
  const std::string b = MakeTempDir("swarmbox_support_test_");
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(b.empty());
  EXPECT_NE(a, b);
  EXPECT_TRUE(fs::is_directory(a));
  EXPECT_TRUE(fs::is_empty(a));
  EXPECT_EQ(fs::path(a).filename().string().rfind("swarmbox_support_test_", 0), 0u);
  fs::remove_all(a);
  fs::remove_all(b);
}

}  // namespace
}  // namespace swarmbox::testing
