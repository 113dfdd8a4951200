#include "swarmbox/experiment/trial_store.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace swarmbox::experiment {

namespace fs = std::filesystem;

Status WriteFileAtomic(const std::string& path, std::string_view text) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return Error(ErrorCode::kIo, std::string("cannot create: ") + std::strerror(errno), tmp);
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int e = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      return Error(ErrorCode::kIo, std::string("cannot write: ") + std::strerror(e), tmp);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    ::unlink(tmp.c_str());
    return Error(ErrorCode::kIo, std::string("cannot sync: ") + std::strerror(errno), tmp);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    ::unlink(tmp.c_str());
    return Error(ErrorCode::kIo, std::string("cannot rename into place: ") + std::strerror(e), path);
  }
  return Ok{};
}

std::string TrialStore::TrialDir(std::string_view id) const {
  return (fs::path(out_) / std::string(id)).string();
}

bool TrialStore::Done(std::string_view id) const {
  std::error_code ec;
  return fs::exists(fs::path(TrialDir(id)) / "result.json", ec);
}

std::vector<PlannedTrial> TrialStore::Pending(const std::vector<PlannedTrial>& all) const {
  std::vector<PlannedTrial> out;
  for (const PlannedTrial& t : all) {
    if (!Done(t.id)) out.push_back(t);
  }
  return out;
}

Result<std::string> TrialStore::Staging(std::string_view id, int attempt) const {
  const fs::path dir = fs::path(out_) / ".staging" / (std::string(id) + "." + std::to_string(attempt));
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::create_directories(dir, ec);
  if (ec) return Error(ErrorCode::kIo, "cannot create the staging folder: " + ec.message(), dir.string());
  return dir.string();
}

Status TrialStore::Commit(std::string_view id, const std::string& finished_dir) const {
  std::error_code ec;
  if (!fs::exists(fs::path(finished_dir) / "result.json", ec)) {
    return Error(ErrorCode::kInternal, "refusing to commit a trial without result.json", finished_dir);
  }
  const std::string target = TrialDir(id);
  if (fs::exists(target, ec)) {
    return Error(ErrorCode::kAlreadyExists, "trial " + std::string(id) + " is already committed",
                 target);
  }
  // The folder's contents are on disk before it appears under its final name.
  if (const int fd = ::open((fs::path(finished_dir) / "result.json").c_str(), O_RDONLY | O_CLOEXEC);
      fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
  if (::rename(finished_dir.c_str(), target.c_str()) != 0) {
    return Error(ErrorCode::kIo, std::string("cannot move the trial into place: ") + std::strerror(errno),
                 target);
  }
  if (const int fd = ::open(out_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
  return Ok{};
}

Status TrialStore::Discard(std::string_view id, int attempt, const std::string& dir) const {
  const fs::path target = fs::path(out_) / ".failed" / (std::string(id) + "." + std::to_string(attempt));
  std::error_code ec;
  fs::create_directories(target.parent_path(), ec);
  fs::remove_all(target, ec);
  fs::rename(dir, target, ec);
  if (ec) return Error(ErrorCode::kIo, "cannot keep the failed attempt: " + ec.message(), dir);
  return Ok{};
}

Status TrialStore::ClearStaging() const {
  std::error_code ec;
  fs::remove_all(fs::path(out_) / ".staging", ec);
  if (ec) return Error(ErrorCode::kIo, "cannot clear staging: " + ec.message(), out_);
  return Ok{};
}

Result<DirLock> DirLock::Acquire(const std::string& out_dir) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) return Error(ErrorCode::kIo, "cannot create the output folder: " + ec.message(), out_dir);
  const std::string path = (fs::path(out_dir) / ".lock").string();
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) return Error(ErrorCode::kIo, std::string("cannot open: ") + std::strerror(errno), path);
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);
    return Error(ErrorCode::kUnavailable,
                 "another swarmbox experiment is running in this folder (it holds " + path + ")",
                 out_dir);
  }
  return DirLock(fd);
}

DirLock::~DirLock() {
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace swarmbox::experiment
