#include "run_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

namespace swarmbox::cli {

namespace {

std::string LockPath(const std::string& run_id) { return RunLockDir() + "/" + run_id + ".lock"; }

bool ValidRunId(const std::string& run_id) {
  return !run_id.empty() && run_id.find('/') == std::string::npos && run_id != "." && run_id != "..";
}

}  // namespace

std::string RunLockDir() {
  const char* env = std::getenv("SWARMBOX_RUN_DIR");
  return env != nullptr && *env != '\0' ? std::string(env) : std::string("/tmp/swarmbox-runs");
}

Result<RunLock> RunLock::Acquire(const std::string& run_id) {
  if (!ValidRunId(run_id)) return Error(ErrorCode::kInvalidArgument, "bad run id '" + run_id + "'");
  const std::string dir = RunLockDir();
  if (::mkdir(dir.c_str(), 01777) == 0) {
    (void)::chmod(dir.c_str(), 01777);  // the umask took bits away: every user's runs live here
  } else if (errno != EEXIST) {
    return Error(ErrorCode::kIo, std::string("cannot create ") + dir + ": " + std::strerror(errno));
  }
  const std::string path = LockPath(run_id);
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) return Error(ErrorCode::kIo, "cannot open " + path + ": " + std::strerror(errno));
  // A gc probing this file holds a shared lock for an instant: retry a little before calling the
  // run id taken.
  int tries = 0;
  while (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    if (err == EWOULDBLOCK && ++tries < 50) {
      ::usleep(2000);
      continue;
    }
    ::close(fd);
    if (err == EWOULDBLOCK) {
      return Error(ErrorCode::kUnavailable, "run " + run_id + " is already running here", path);
    }
    return Error(ErrorCode::kIo, "cannot lock " + path + ": " + std::strerror(err));
  }
  return RunLock(fd, path);
}

RunLock::RunLock(RunLock&& other) noexcept : fd_(other.fd_), path_(std::move(other.path_)) {
  other.fd_ = -1;
}

RunLock& RunLock::operator=(RunLock&& other) noexcept {
  if (this != &other) {
    Release();
    fd_ = other.fd_;
    path_ = std::move(other.path_);
    other.fd_ = -1;
  }
  return *this;
}

RunLock::~RunLock() { Release(); }

void RunLock::Release() {
  if (fd_ < 0) return;
  (void)::unlink(path_.c_str());  // while still holding it: a concurrent gc sees live or nothing
  ::close(fd_);
  fd_ = -1;
}

bool IsRunLive(const std::string& run_id) {
  if (!ValidRunId(run_id)) return false;
  const int fd = ::open(LockPath(run_id).c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  // A shared lock is refused only while someone holds the exclusive one.
  const bool live = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);
  return live;
}

}  // namespace swarmbox::cli
