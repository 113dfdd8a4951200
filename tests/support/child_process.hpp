// ChildProcess: a program started from an argv array (no shell) by a test or a benchmark,
// signalled, waited for with a deadline, and never left behind:
//   - the child runs in its own process group; destroying a ChildProcess that still runs SIGKILLs
//     that group and reaps the child, so every exit path of a test (a failed ASSERT included)
//     ends the program and whatever it started;
//   - the child gets SIGKILL when the thread that spawned it dies (PR_SET_PDEATHSIG), e.g. when
//     ctest kills the test at its TIMEOUT;
//   - it starts with default signal handling and nothing blocked, whatever this process (gtest, a
//     DDS library) installed, and with stdin on /dev/null.
//
//   auto child = ChildProcess::Spawn({swarmbox, "run", trial}, "out.txt", "err.txt");
//   if (!child) ...;                         // the program could not be started (kIo, where=argv[0])
//   child->Signal(SIGINT);
//   std::optional<int> code = child->Wait(std::chrono::seconds(60));   // nullopt: still running
//
// Exit codes: the program's own, or 128 + N when signal N ended it (as a shell reports it).
// argv[0] is a path (no PATH search). Not thread-safe; one owner.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::testing {

struct SpawnOptions {
  // Files the child's stdout and stderr go to (created or truncated, 0644). Empty: this
  // process's own stream. The same path for both: one file with both streams (2>&1).
  std::string stdout_path;
  std::string stderr_path;
  // The child's working directory (the redirections above are opened first, relative to this
  // process's). Empty: this process's own.
  std::string working_dir = {};  // (initialised: designated initialisers may leave it out)
};

class ChildProcess {
 public:
  // kInvalidArgument for an empty argv; kIo (where = argv[0]) when fork or exec fails.
  static Result<ChildProcess> Spawn(const std::vector<std::string>& argv, const SpawnOptions& options = {});
  // stdout and stderr to these files; "" for a path = /dev/null.
  static Result<ChildProcess> Spawn(const std::vector<std::string>& argv, const std::string& stdout_path,
                                    const std::string& stderr_path);

  ChildProcess(ChildProcess&& other) noexcept;
  ChildProcess& operator=(ChildProcess&& other) noexcept;
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ~ChildProcess();  // SIGKILLs the child's process group if the child still runs, and reaps it

  pid_t pid() const { return pid_; }
  // True until the child has exited (checks without blocking, and reaps it when it has).
  bool running();

  // Sends `signal` to the child (not its group) while it runs; false once it has been reaped.
  bool Signal(int signal);

  // Waits for the exit at most `timeout` (polling every millisecond); the exit code, or nullopt
  // while it still runs.
  std::optional<int> Wait(std::chrono::milliseconds timeout);

  // SIGTERM, then SIGKILL to its process group after `grace`; reaps it and returns the exit code
  // (-1 for a moved-from object). Idempotent: later calls return the same code.
  int Stop(std::chrono::milliseconds grace);

 private:
  explicit ChildProcess(pid_t pid) : pid_(pid) {}
  bool Reap(bool block);
  void KillAndReap();

  pid_t pid_ = -1;
  std::optional<int> code_;
};

// Spawns, waits at most `timeout` (then SIGKILL: the result is a kTimeout error) and returns the
// exit code with what the program printed (through files in `scratch_dir`, removed afterwards).
struct Finished {
  int code = 0;
  std::string out;
  std::string err;
};
Result<Finished> RunToEnd(const std::vector<std::string>& argv, std::chrono::milliseconds timeout,
                          const std::string& scratch_dir);

// Path of the running executable (/proc/self/exe), for re-executing oneself in another role.
std::string SelfExecutable();

}  // namespace swarmbox::testing
