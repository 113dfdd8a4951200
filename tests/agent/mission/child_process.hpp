// Child processes for the mission integration tests: posix_spawn with an argument vector (no
// shell), stdout and stderr to a file, kill and reap by pid. A Child still running when it is
// destroyed is SIGKILLed and reaped, so every exit path of a test (including a failed ASSERT)
// leaves no process behind. Not thread-safe: one test thread owns its children.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

namespace swarmbox::mission::testing {

class Child {
 public:
  // Starts `argv[0]` (a path) with `argv`, stdout and stderr to `log_path` (truncated).
  // running() is false when the spawn failed.
  Child(const std::vector<std::string>& argv, std::string log_path);
  ~Child();
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  bool running() const { return pid_ > 0 && !reaped_; }
  pid_t pid() const { return pid_; }
  void Signal(int sig);  // no-op once reaped
  // Waits for the exit: the exit code, 128 + signal when killed, -1 on timeout.
  int Wait(std::chrono::milliseconds timeout);
  std::string ReadLog() const;
  const std::string& log_path() const { return log_path_; }

 private:
  pid_t pid_ = -1;
  bool reaped_ = false;
  int code_ = -1;
  std::string log_path_;
};

// A fresh, empty directory under /tmp.
std::string MakeTempDir(const std::string& prefix);

}  // namespace swarmbox::mission::testing
