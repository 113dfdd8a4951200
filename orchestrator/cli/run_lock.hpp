// Which runs are alive on this machine, so `swarmbox gc` never removes a running trial.
//
//   auto lock = RunLock::Acquire(run_id);   // swarmbox run / experiment, for the whole run
//   ...                                     // held until the process ends, however it ends
//   IsRunLive(run_id)                       // swarmbox gc: true while that process lives
//
// A run holds an advisory lock (flock) on `<dir>/<run id>.lock` (dir: $SWARMBOX_RUN_DIR, default
// /tmp/swarmbox-runs, created sticky and world-writable so every user's gc sees every user's runs).
// The kernel drops the lock when the process dies, also on SIGKILL or a crash: exactly the runs
// whose leftovers gc is for. Runs started on another machine are not seen here; their resources on
// this engine are collected like those of a dead run (`gc --run ID` is always explicit).
#pragma once

#include <string>
#include <utility>

#include "swarmbox/common/result.hpp"

namespace swarmbox::cli {

std::string RunLockDir();

class RunLock {
 public:
  // kInvalidArgument: run id with '/' or empty; kIo: the folder or file cannot be made;
  // kUnavailable: another live process holds this run id.
  static Result<RunLock> Acquire(const std::string& run_id);

  RunLock(RunLock&& other) noexcept;
  RunLock& operator=(RunLock&& other) noexcept;
  RunLock(const RunLock&) = delete;
  RunLock& operator=(const RunLock&) = delete;
  ~RunLock();  // unlocks and removes the file

 private:
  RunLock(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
  void Release();
  int fd_ = -1;
  std::string path_;
};

// True while some process holds the run's lock. A missing file or an unheld lock is a dead run.
bool IsRunLive(const std::string& run_id);

}  // namespace swarmbox::cli
