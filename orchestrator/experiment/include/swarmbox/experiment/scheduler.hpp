// Scheduling an experiment's trials over a pool of hosts: a work queue over every slot of every
// host (not replication). A host whose attempt fails as a host (engine gone, tunnel down) leaves
// the pool; the trial it was running goes back to the queue for the other hosts, at most
// `max_attempts` attempts in all, after which it is "exhausted" (the caller records outcome
// `error` with the reason). The run never stops for one bad host; when no host is left, the
// trials not run stay without a result (a later --resume runs them).
//
//   WorkQueue  the pure state machine (deterministic, unit-tested step by step)
//   RunSchedule  the threaded driver: one thread per slot, each taking from the queue
//
//   struct MyHost : HostWorker { ... AttemptResult Run(const PlannedTrial&, int attempt) ...};
//   auto reports = RunSchedule(trials, {&local, &remote}, {.max_attempts = 3}, observer);
#pragma once

#include <atomic>
#include <cstddef>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "swarmbox/experiment/experiment_spec.hpp"

namespace swarmbox::experiment {

struct AttemptResult {
  enum class Kind {
    kCompleted,   // the trial reached an outcome (any outcome) and its folder is committed
    kHostFailed,  // the host failed under the trial: re-queue it elsewhere, drop the host
    kCancelled,   // stopped by the user: the trial stays without result
  };
  Kind kind = Kind::kCompleted;
  std::string outcome;  // kCompleted: success|failure|timeout|error
  std::string reason;   // kHostFailed: why; kCompleted: the trial's reason
};

enum class TrialStatus { kPending, kRunning, kCompleted, kExhausted, kNotRun };

struct TrialReport {
  TrialStatus status = TrialStatus::kPending;
  int attempts = 0;           // attempts started
  std::string host;           // the host of the last attempt
  std::string outcome;        // kCompleted
  std::string reason;         // kCompleted: the trial's; kExhausted/kNotRun: why
};

// The pure queue. Hosts and trials are indices. Not thread-safe (RunSchedule locks around it).
class WorkQueue {
 public:
  WorkQueue(std::size_t trials, std::vector<std::string> hosts, int max_attempts);

  // The next trial for `host`, marked running there; nullopt when there is nothing for it now
  // (queue empty, host down, or stopping).
  std::optional<std::size_t> Take(std::size_t host);
  // The end of an attempt started by Take().
  void Report(std::size_t host, std::size_t trial, const AttemptResult& result);
  // Takes a host out of the pool (also done by Report on kHostFailed). When no host is left,
  // every pending trial becomes kNotRun.
  void HostDown(std::size_t host, const std::string& reason);
  // Stop handing out work (Ctrl-C): pending trials become kNotRun once nothing runs.
  void Stop(const std::string& reason);

  bool host_up(std::size_t host) const { return host_up_[host]; }
  const std::string& host_down_reason(std::size_t host) const { return host_reason_[host]; }
  // Nothing pending that a live host could take and nothing running.
  bool Finished() const;
  std::size_t running() const { return running_; }
  const std::vector<TrialReport>& reports() const { return reports_; }

 private:
  void AbandonPending(const std::string& reason);

  std::vector<std::string> hosts_;
  std::vector<bool> host_up_;
  std::vector<std::string> host_reason_;
  int max_attempts_;
  std::deque<std::size_t> pending_;
  std::vector<TrialReport> reports_;
  std::vector<std::vector<std::string>> failures_;  // per trial: "host: reason" of each failure
  std::size_t running_ = 0;
  bool stopping_ = false;
  std::string stop_reason_;
};

// One host as the scheduler sees it.
class HostWorker {
 public:
  virtual ~HostWorker() = default;
  virtual std::string name() const = 0;
  virtual int slots() const = 0;
  // Runs one attempt (blocking). Called from up to slots() threads at once: thread-safe.
  // `attempt` is 1-based over the trial's whole life (all hosts).
  virtual AttemptResult Run(const PlannedTrial& trial, int attempt) = 0;
};

// Callbacks from the slot threads; calls are serialised (one at a time).
class ScheduleObserver {
 public:
  virtual ~ScheduleObserver() = default;
  virtual void OnStart(const std::string& /*host*/, const PlannedTrial& /*trial*/, int /*attempt*/) {}
  virtual void OnFinish(const std::string& /*host*/, const PlannedTrial& /*trial*/,
                        const AttemptResult& /*result*/) {}
  virtual void OnHostDown(const std::string& /*host*/, const std::string& /*reason*/) {}
  // A trial ran out of attempts: record its error outcome (called once per such trial).
  virtual void OnExhausted(const PlannedTrial& /*trial*/, const std::string& /*reason*/) {}
};

struct ScheduleOptions {
  int max_attempts = 3;
  const std::atomic<bool>* interrupted = nullptr;  // checked between attempts
};

// Runs every trial (blocking) and returns one report per trial, in the order of `trials`.
std::vector<TrialReport> RunSchedule(const std::vector<PlannedTrial>& trials,
                                     const std::vector<HostWorker*>& hosts,
                                     const ScheduleOptions& options, ScheduleObserver& observer);

}  // namespace swarmbox::experiment
