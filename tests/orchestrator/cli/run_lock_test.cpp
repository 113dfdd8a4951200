// Live runs and `swarmbox gc`: the run lock (flock, released by the kernel however the process
// ends) and which runs gc removes.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>

#include "commands.hpp"
#include "run_lock.hpp"

namespace swarmbox::cli {
namespace {

namespace fs = std::filesystem;

class RunLockTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("swarmbox-run-lock-test-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    ::setenv("SWARMBOX_RUN_DIR", dir_.c_str(), 1);
  }
  void TearDown() override {
    ::unsetenv("SWARMBOX_RUN_DIR");
    fs::remove_all(dir_);
  }
  fs::path dir_;
};

TEST_F(RunLockTest, HeldWhileAliveAndGoneWithTheLock) {
  EXPECT_FALSE(IsRunLive("r1"));
  {
    auto lock = RunLock::Acquire("r1");
    ASSERT_TRUE(lock) << lock.error().ToString();
    EXPECT_TRUE(IsRunLive("r1"));
    EXPECT_FALSE(IsRunLive("r2"));
    // The folder is shared by every user's runs.
    EXPECT_EQ(fs::status(dir_).permissions() & fs::perms::all, fs::perms::all);
    EXPECT_NE(fs::status(dir_).permissions() & fs::perms::sticky_bit, fs::perms::none);
    auto again = RunLock::Acquire("r1");
    ASSERT_FALSE(again);
    EXPECT_EQ(again.error().code(), ErrorCode::kUnavailable);
    RunLock moved = std::move(*lock);
    EXPECT_TRUE(IsRunLive("r1"));
  }
  EXPECT_FALSE(IsRunLive("r1"));
  EXPECT_FALSE(fs::exists(dir_ / "r1.lock"));
  EXPECT_EQ(RunLock::Acquire("a/b").error().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(RunLock::Acquire("").error().code(), ErrorCode::kInvalidArgument);
}

TEST_F(RunLockTest, AKilledRunIsDeadAndItsIdCanBeTakenAgain) {
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    auto lock = RunLock::Acquire("killed");
    const char ok = lock ? 'y' : 'n';
    (void)::write(ready[1], &ok, 1);
    ::pause();  // until SIGKILL: no destructor runs, the file stays, the kernel drops the lock
    std::_Exit(0);
  }
  ::close(ready[1]);
  char ok = 0;
  ASSERT_EQ(::read(ready[0], &ok, 1), 1);
  ::close(ready[0]);
  ASSERT_EQ(ok, 'y');
  EXPECT_TRUE(IsRunLive("killed"));
  ::kill(child, SIGKILL);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(fs::exists(dir_ / "killed.lock"));
  EXPECT_FALSE(IsRunLive("killed"));
  EXPECT_TRUE(RunLock::Acquire("killed"));
}

TEST(PlanGc, EveryDeadRunButNoLiveOneAndAnExplicitRunAlways) {
  auto live = [](const std::string& run) { return run == "running"; };
  GcPlan all = PlanGc({"dead-1", "running", "dead-2"}, "", live);
  EXPECT_EQ(all.remove, (std::vector<std::string>{"dead-1", "dead-2"}));
  EXPECT_EQ(all.skip_live, (std::vector<std::string>{"running"}));
  GcPlan one = PlanGc({"dead-1", "running"}, "running", live);
  EXPECT_EQ(one.remove, (std::vector<std::string>{"running"}));
  EXPECT_TRUE(one.skip_live.empty());
  EXPECT_TRUE(PlanGc({}, "", live).remove.empty());
}

}  // namespace
}  // namespace swarmbox::cli
