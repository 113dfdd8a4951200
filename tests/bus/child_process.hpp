// A child process for two-process bus tests and benchmarks: spawned from an argv array (no
// shell), killed and reaped when the object goes away, so it dies on every exit path of the
// parent (including a failed ASSERT); it also gets SIGKILL if the parent process dies first
// (PR_SET_PDEATHSIG).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::bus::testing {

class ChildProcess {
 public:
  // argv[0] is the executable's path. kIo if fork/exec fails (an exec failure shows up as exit
  // code 127 of the child).
  static Result<ChildProcess> Spawn(const std::vector<std::string>& argv);

  ChildProcess(ChildProcess&& other) noexcept : pid_(other.pid_) { other.pid_ = -1; }
  ChildProcess& operator=(ChildProcess&& other) noexcept;
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ~ChildProcess() { Stop(std::chrono::seconds(2)); }

  // SIGTERM, then SIGKILL after `grace`; reaps the child. Returns its wait status, or -1 if there
  // was no child. Idempotent.
  int Stop(std::chrono::milliseconds grace);

  // True while the child has not exited (reaps it if it has).
  bool Running();

  pid_t pid() const { return pid_; }

 private:
  explicit ChildProcess(pid_t pid) : pid_(pid) {}
  pid_t pid_ = -1;
  int status_ = -1;
};

// Path of the running executable (/proc/self/exe), for re-executing oneself in another role.
std::string SelfExecutable();

}  // namespace swarmbox::bus::testing
