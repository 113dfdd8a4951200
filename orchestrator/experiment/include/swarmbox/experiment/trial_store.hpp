// The experiment folder on disk, and the rule that makes --resume safe: a trial folder
// <out>/<trial id>/ exists only complete, with its result.json (contract).
//
//   <out>/experiment.json        name, run id, factors, the experiment file
//   <out>/<trial id>/            committed trials (result.json, trial_meta.json, logs/, ...)
//   <out>/.staging/<id>.<n>/     attempt n while it runs (the runner writes here)
//   <out>/.failed/<id>.<n>/      attempts lost with their host, kept for inspection
//   <out>/.lock                  held (flock) while an experiment runs in the folder
//
// A finished attempt is committed by one rename(2) of its folder to <out>/<trial id>: the folder
// appears whole or not at all, so a crash at any point leaves either a committed trial (never
// run again) or only staging (cleared and run again by --resume). A trial is never committed
// twice: Commit refuses when the target exists.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/experiment/experiment_spec.hpp"

namespace swarmbox::experiment {

// Writes `text` to `path` through a temporary file, fsync and rename (atomic replace).
Status WriteFileAtomic(const std::string& path, std::string_view text);

class TrialStore {
 public:
  explicit TrialStore(std::string out_dir) : out_(std::move(out_dir)) {}

  const std::string& out_dir() const { return out_; }
  std::string TrialDir(std::string_view id) const;
  // Committed (<out>/<id>/result.json exists).
  bool Done(std::string_view id) const;
  // The trials of `all` that are not committed, in order.
  std::vector<PlannedTrial> Pending(const std::vector<PlannedTrial>& all) const;
  // A fresh, empty <out>/.staging/<id>.<attempt>/.
  Result<std::string> Staging(std::string_view id, int attempt) const;
  // Renames `finished_dir` (which must hold result.json) to <out>/<id>.
  Status Commit(std::string_view id, const std::string& finished_dir) const;
  // Moves an attempt's folder to <out>/.failed/<id>.<attempt> (best effort; returns the error).
  Status Discard(std::string_view id, int attempt, const std::string& dir) const;
  // Removes <out>/.staging (what a crashed run left).
  Status ClearStaging() const;

 private:
  std::string out_;
};

// An exclusive lock on <out>/.lock for the life of the object (flock; released by the kernel if
// the process dies). kUnavailable when another process holds it.
class DirLock {
 public:
  static Result<DirLock> Acquire(const std::string& out_dir);
  DirLock(DirLock&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
  DirLock& operator=(DirLock&&) = delete;
  DirLock(const DirLock&) = delete;
  ~DirLock();

 private:
  explicit DirLock(int fd) : fd_(fd) {}
  int fd_;
};

}  // namespace swarmbox::experiment
