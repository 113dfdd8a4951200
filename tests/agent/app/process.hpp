// Child processes for the agent's program tests: posix_spawn with an argument vector (no shell),
// stdout and stderr to a file, wait with a deadline, kill by pid.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

namespace swarmbox::agent::testing {

class Child {
 public:
  // Starts `argv[0]` with `argv`, output (stdout and stderr) to `log_path`. pid() <= 0 on failure.
  Child(const std::vector<std::string>& argv, const std::string& log_path);
  ~Child();  // kills (SIGKILL) and reaps a child still running
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  pid_t pid() const { return pid_; }
  // Waits for the exit; the exit code, or -1 on timeout (still running), or 128+signal.
  int Wait(std::chrono::milliseconds timeout);
  void Terminate();  // SIGTERM
  void Signal(int sig);  // no-op once reaped
  bool running() const { return pid_ > 0 && !reaped_; }
  std::string ReadLog() const;
  const std::string& log_path() const { return log_path_; }

 private:
  pid_t pid_ = -1;
  bool reaped_ = false;
  int code_ = -1;
  std::string log_path_;
};

// A fresh, empty temporary directory for one test's logs.
std::string MakeTempDir(const std::string& prefix);

}  // namespace swarmbox::agent::testing
