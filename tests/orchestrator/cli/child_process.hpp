// ChildProcess: a program started from an argv array (posix_spawn, no shell) with its stdout and
// stderr written to files, signalled and waited for with a deadline. Used by the end-to-end tests
// of the `swarmbox` program and by `swarmbox-bench launch`, which drive real binaries.
//
//   auto child = ChildProcess::Spawn({swarmbox, "run", trial, "--out", dir}, "out.txt", "err.txt");
//   if (!child) ...;                               // the program could not be started
//   child->Signal(SIGINT);
//   std::optional<int> code = child->Wait(std::chrono::seconds(60));   // nullopt: still running
//
// Exit codes: the program's own, or 128 + N when signal N ended it (as a shell reports it).
// The destructor SIGKILLs and reaps a child that is still running, so a failing test leaves no
// process behind. Not thread-safe; one owner.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::cli::testing {

class ChildProcess {
 public:
  // "" for a path = /dev/null.
  static Result<ChildProcess> Spawn(const std::vector<std::string>& argv,
                                    const std::string& stdout_path,
                                    const std::string& stderr_path);

  ChildProcess(ChildProcess&& other) noexcept;
  ChildProcess& operator=(ChildProcess&& other) noexcept;
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ~ChildProcess();

  pid_t pid() const { return pid_; }
  bool running() const { return !code_.has_value(); }

  // Sends `signal` while the child runs; false once it has been reaped.
  bool Signal(int signal);

  // Waits for the exit at most `timeout` (polling every millisecond); the exit code, or nullopt
  // while it still runs.
  std::optional<int> Wait(std::chrono::milliseconds timeout);

 private:
  explicit ChildProcess(pid_t pid) : pid_(pid) {}
  bool Reap(bool block);
  void KillAndReap();

  pid_t pid_ = -1;
  std::optional<int> code_;
};

// Spawns, waits at most `timeout` (then SIGKILL: the result is an kTimeout error) and returns the
// exit code with what the program printed.
struct Finished {
  int code = 0;
  std::string out;
  std::string err;
};
Result<Finished> RunToEnd(const std::vector<std::string>& argv, std::chrono::milliseconds timeout,
                          const std::string& scratch_dir);

std::string ReadWholeFile(const std::string& path);

}  // namespace swarmbox::cli::testing
