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

std::vector<TrialReport> RunSchedule(const std::vector<PlannedTrial>& trials,
                                     const std::vector<HostWorker*>& hosts,
                                     const ScheduleOptions& options, ScheduleObserver& observer) {
  std::vector<std::string> names;
  for (HostWorker* h : hosts) names.push_back(h->name());
  WorkQueue queue(trials.size(), names, options.max_attempts);
  std::mutex mu;
  std::condition_variable cv;
  std::mutex observer_mu;

  auto interrupted = [&] { return options.interrupted != nullptr && options.interrupted->load(); };

  auto slot = [&](std::size_t h) {
    while (true) {
      std::optional<std::size_t> t;
      int attempt = 0;
      {
        std::unique_lock lock(mu);
        while (true) {
          if (interrupted()) queue.Stop("interrupted (Ctrl-C)");
          t = queue.Take(h);
          if (t || queue.Finished() || !queue.host_up(h) || interrupted()) break;
          // Work may come back (a failed host's trial is re-queued): wait for a report.
          cv.wait_for(lock, std::chrono::milliseconds(200));
        }
        if (!t) {
          cv.notify_all();
          return;
        }
        attempt = queue.reports()[*t].attempts;
      }
      {
        std::lock_guard olock(observer_mu);
        observer.OnStart(names[h], trials[*t], attempt);
      }
      AttemptResult result = hosts[h]->Run(trials[*t], attempt);
      bool exhausted = false;
      bool went_down = false;
      std::string down_reason;
      {
        std::lock_guard lock(mu);
        const bool was_up = queue.host_up(h);
        queue.Report(h, *t, result);
        exhausted = queue.reports()[*t].status == TrialStatus::kExhausted;
        went_down = was_up && !queue.host_up(h);
        down_reason = queue.host_down_reason(h);
      }
      {
        std::lock_guard olock(observer_mu);
        observer.OnFinish(names[h], trials[*t], result);
        if (went_down) observer.OnHostDown(names[h], down_reason);
        if (exhausted) {
          std::string reason;
          {
            std::lock_guard lock(mu);
            reason = queue.reports()[*t].reason;
          }
          observer.OnExhausted(trials[*t], reason);
        }
      }
      cv.notify_all();
    }
  };

  std::vector<std::thread> threads;
  for (std::size_t h = 0; h < hosts.size(); ++h) {
    for (int s = 0; s < std::max(1, hosts[h]->slots()); ++s) threads.emplace_back(slot, h);
  }
  for (std::thread& th : threads) th.join();
  std::lock_guard lock(mu);
  if (!queue.Finished()) queue.Stop("stopped");
  return queue.reports();
}

}  // namespace swarmbox::experiment
