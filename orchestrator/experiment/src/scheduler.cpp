#include "swarmbox/experiment/scheduler.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace swarmbox::experiment {

WorkQueue::WorkQueue(std::size_t trials, std::vector<std::string> hosts, int max_attempts)
    : hosts_(std::move(hosts)),
      host_up_(hosts_.size(), true),
      host_reason_(hosts_.size()),
      max_attempts_(std::max(1, max_attempts)),
      reports_(trials),
      failures_(trials) {
  for (std::size_t i = 0; i < trials; ++i) pending_.push_back(i);
  if (hosts_.empty()) AbandonPending("no hosts in the pool");
}

std::optional<std::size_t> WorkQueue::Take(std::size_t host) {
  if (stopping_ || !host_up_[host] || pending_.empty()) return std::nullopt;
  const std::size_t t = pending_.front();
  pending_.pop_front();
  TrialReport& r = reports_[t];
  r.status = TrialStatus::kRunning;
  r.attempts += 1;
  r.host = hosts_[host];
  ++running_;
  return t;
}

void WorkQueue::Report(std::size_t host, std::size_t trial, const AttemptResult& result) {
  SWARMBOX_CHECK(running_ > 0 && reports_[trial].status == TrialStatus::kRunning);
  --running_;
  TrialReport& r = reports_[trial];
  switch (result.kind) {
    case AttemptResult::Kind::kCompleted:
      r.status = TrialStatus::kCompleted;
      r.outcome = result.outcome;
      r.reason = result.reason;
      break;
    case AttemptResult::Kind::kCancelled:
      r.status = TrialStatus::kNotRun;
      r.attempts -= 1;  // an interrupted attempt does not count against the trial
      r.reason = result.reason.empty() ? "interrupted" : result.reason;
      break;
    case AttemptResult::Kind::kHostFailed: {
      failures_[trial].push_back(hosts_[host] + ": " + result.reason);
      if (r.attempts >= max_attempts_) {
        r.status = TrialStatus::kExhausted;
        std::string why = "gave up after " + std::to_string(r.attempts) + " attempts (";
        for (std::size_t i = 0; i < failures_[trial].size(); ++i) {
          why += (i == 0 ? "" : "; ") + failures_[trial][i];
        }
        r.reason = why + ")";
      } else {
        r.status = TrialStatus::kPending;
        pending_.push_front(trial);  // first in line for the hosts that are left
      }
      HostDown(host, result.reason);
      break;
    }
  }
  if (stopping_ && running_ == 0) AbandonPending(stop_reason_);
}

void WorkQueue::HostDown(std::size_t host, const std::string& reason) {
  if (!host_up_[host]) return;
  host_up_[host] = false;
  host_reason_[host] = reason;
  if (std::none_of(host_up_.begin(), host_up_.end(), [](bool up) { return up; })) {
    AbandonPending("no host left in the pool (last: " + hosts_[host] + ": " + reason + ")");
  }
}

void WorkQueue::Stop(const std::string& reason) {
  stopping_ = true;
  stop_reason_ = reason;
  if (running_ == 0) AbandonPending(reason);
}

void WorkQueue::AbandonPending(const std::string& reason) {
  for (std::size_t t : pending_) {
    reports_[t].status = TrialStatus::kNotRun;
    reports_[t].reason = reason;
  }
  pending_.clear();
}

bool WorkQueue::Finished() const { return pending_.empty() && running_ == 0; }

namespace {

// RunSchedule's shared state: the queue under `mu_` (slots wait on `cv_` for work to come back),
// the observer's calls serialised by `observer_mu_` (taken before `mu_` where both are held).
class ScheduleRun {
 public:
  ScheduleRun(const std::vector<PlannedTrial>& trials, const std::vector<HostWorker*>& hosts,
              const ScheduleOptions& options, ScheduleObserver& observer)
      : trials_(trials), hosts_(hosts), options_(options), observer_(observer), names_(HostNames(hosts)),
        queue_(trials.size(), names_, options.max_attempts) {}

  // One thread per slot of every host, until the queue has nothing more for them.
  std::vector<TrialReport> Run() {
    std::vector<std::thread> threads;
    for (std::size_t h = 0; h < hosts_.size(); ++h) {
      for (int s = 0; s < std::max(1, hosts_[h]->slots()); ++s) threads.emplace_back([this, h] { Slot(h); });
    }
    for (std::thread& th : threads) th.join();
    std::lock_guard lock(mu_);
    if (!queue_.Finished()) queue_.Stop("stopped");
    return queue_.reports();
  }

 private:
  struct Taken {
    std::size_t trial = 0;
    int attempt = 0;
  };

  static std::vector<std::string> HostNames(const std::vector<HostWorker*>& hosts) {
    std::vector<std::string> names;
    for (HostWorker* h : hosts) names.push_back(h->name());
    return names;
  }

  bool Interrupted() const { return options_.interrupted != nullptr && options_.interrupted->load(); }

  // One slot of host `h`: takes trials and runs them one after another.
  void Slot(std::size_t h) {
    while (std::optional<Taken> taken = Take(h)) {
      {
        std::lock_guard olock(observer_mu_);
        observer_.OnStart(names_[h], trials_[taken->trial], taken->attempt);
      }
      const AttemptResult result = hosts_[h]->Run(trials_[taken->trial], taken->attempt);
      Finish(h, taken->trial, result);
      cv_.notify_all();
    }
  }

  // The next trial for host `h`, waiting while work may come back (a failed host's trial is
  // re-queued); nullopt when the slot is done (the other slots are woken to see it too).
  std::optional<Taken> Take(std::size_t h) {
    std::unique_lock lock(mu_);
    std::optional<std::size_t> t;
    while (true) {
      if (Interrupted()) queue_.Stop("interrupted (Ctrl-C)");
      t = queue_.Take(h);
      if (t || queue_.Finished() || !queue_.host_up(h) || Interrupted()) break;
      cv_.wait_for(lock, kWaitForReport);
    }
    if (!t) {
      cv_.notify_all();
      return std::nullopt;
    }
    return Taken{*t, queue_.reports()[*t].attempts};
  }

  // The attempt's result into the queue, then to the observer (the host's fall and the trial's
  // exhaustion with it).
  void Finish(std::size_t h, std::size_t t, const AttemptResult& result) {
    bool exhausted = false;
    bool went_down = false;
    std::string down_reason;
    {
      std::lock_guard lock(mu_);
      const bool was_up = queue_.host_up(h);
      queue_.Report(h, t, result);
      exhausted = queue_.reports()[t].status == TrialStatus::kExhausted;
      went_down = was_up && !queue_.host_up(h);
      down_reason = queue_.host_down_reason(h);
    }
    std::lock_guard olock(observer_mu_);
    observer_.OnFinish(names_[h], trials_[t], result);
    if (went_down) observer_.OnHostDown(names_[h], down_reason);
    if (exhausted) {
      std::string reason;
      {
        std::lock_guard lock(mu_);
        reason = queue_.reports()[t].reason;
      }
      observer_.OnExhausted(trials_[t], reason);
    }
  }

  // How long an idle slot waits for a report before it looks at the queue (and Ctrl-C) again.
  static constexpr std::chrono::milliseconds kWaitForReport{200};

  const std::vector<PlannedTrial>& trials_;
  const std::vector<HostWorker*>& hosts_;
  const ScheduleOptions& options_;
  ScheduleObserver& observer_;
  const std::vector<std::string> names_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::mutex observer_mu_;
  WorkQueue queue_;  // under mu_
};

}  // namespace

std::vector<TrialReport> RunSchedule(const std::vector<PlannedTrial>& trials,
                                     const std::vector<HostWorker*>& hosts,
                                     const ScheduleOptions& options, ScheduleObserver& observer) {
  ScheduleRun run(trials, hosts, options, observer);
  return run.Run();
}

}  // namespace swarmbox::experiment
