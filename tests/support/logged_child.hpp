// LoggedChild: a ChildProcess whose stdout and stderr go to one log file, for the tests that run
// the project's programs (swarmbox-physics, swarmbox-agent, swarmbox-raft-node) side by side and
// read what they print. Same guarantees as ChildProcess: a child still running when the object is
// destroyed is SIGKILLed with its process group and reaped.
//
//   LoggedChild agent({SWARMBOX_AGENT_BIN, "--name", "drone_1"}, dir + "/drone_1.log");
//   ASSERT_TRUE(agent.running()) << agent.spawn_error();
//   ASSERT_TRUE(agent.WaitForLog("event=ready", 30s)) << agent.ReadLog();
//   agent.Terminate();
//   EXPECT_EQ(agent.Wait(10s), 0) << agent.ReadLog();
#pragma once

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "support/child_process.hpp"

namespace swarmbox::testing {

class LoggedChild {
 public:
  // Starts `argv[0]` (a path) with `argv`, stdout and stderr to `log_path` (truncated). When the
  // spawn fails, pid() is -1, running() false and spawn_error() says why.
  LoggedChild(const std::vector<std::string>& argv, std::string log_path);
  LoggedChild(const LoggedChild&) = delete;
  LoggedChild& operator=(const LoggedChild&) = delete;

  pid_t pid() const { return process_ ? process_->pid() : -1; }
  // True until the child has exited (reaps it when it has).
  bool running() { return process_ && process_->running(); }
  bool Signal(int sig);  // to the child; false (nothing sent) once it has been reaped
  bool Terminate();      // SIGTERM
  // Waits for the exit: the exit code, 128 + signal when killed, -1 on timeout (still running)
  // or when the spawn failed.
  int Wait(std::chrono::milliseconds timeout);
  // Waits until the log contains `text` (true), or the child has exited without printing it, or
  // `timeout` has passed (false). Polls the file every 10 ms.
  bool WaitForLog(std::string_view text, std::chrono::milliseconds timeout);

  std::string ReadLog() const;
  const std::string& log_path() const { return log_path_; }
  const std::string& spawn_error() const { return spawn_error_; }

 private:
  std::string log_path_;
  std::optional<ChildProcess> process_;
  std::string spawn_error_;
};

}  // namespace swarmbox::testing
