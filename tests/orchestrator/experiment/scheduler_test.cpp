// Scheduling over a pool of hosts: the pure work queue step by step, then the threaded driver on a
// fake host pool (hosts that fail after N trials, hosts that are down from the start).
#include "swarmbox/experiment/scheduler.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <map>
#include <mutex>
#include <set>
#include <thread>

namespace swarmbox::experiment {
namespace {

AttemptResult Completed(std::string outcome = "success") {
  return {AttemptResult::Kind::kCompleted, std::move(outcome), ""};
}
AttemptResult HostFailed(std::string why) {
  return {AttemptResult::Kind::kHostFailed, "", std::move(why)};
}

TEST(WorkQueue, HandsOutInOrderAndFinishes) {
  WorkQueue q(3, {"local", "remote"}, 3);
  EXPECT_EQ(q.Take(0), 0u);
  EXPECT_EQ(q.Take(1), 1u);
  EXPECT_EQ(q.Take(0), 2u);
  EXPECT_FALSE(q.Take(1).has_value());
  EXPECT_FALSE(q.Finished());
  q.Report(0, 0, Completed());
  q.Report(1, 1, Completed("timeout"));
  q.Report(0, 2, Completed());
  EXPECT_TRUE(q.Finished());
  EXPECT_EQ(q.reports()[1].status, TrialStatus::kCompleted);
  EXPECT_EQ(q.reports()[1].outcome, "timeout");
  EXPECT_EQ(q.reports()[1].host, "remote");
}

TEST(WorkQueue, AFailedHostLeavesAndItsTrialGoesFirstToTheOthers) {
  WorkQueue q(3, {"local", "remote"}, 3);
  ASSERT_EQ(q.Take(0), 0u);
  ASSERT_EQ(q.Take(1), 1u);
  q.Report(1, 1, HostFailed("dockerd gone"));
  EXPECT_FALSE(q.host_up(1));
  EXPECT_EQ(q.host_down_reason(1), "dockerd gone");
  EXPECT_FALSE(q.Take(1).has_value());  // out of the pool
  EXPECT_EQ(q.Take(0), 1u);             // re-queued at the front
  EXPECT_EQ(q.reports()[1].attempts, 2);
  q.Report(0, 1, Completed());
  q.Report(0, 0, Completed());
  EXPECT_EQ(q.Take(0), 2u);
  q.Report(0, 2, Completed());
  EXPECT_TRUE(q.Finished());
  for (const TrialReport& r : q.reports()) EXPECT_EQ(r.status, TrialStatus::kCompleted);
}

TEST(WorkQueue, BoundedAttemptsThenExhaustedWithEveryReason) {
  WorkQueue q(1, {"h1", "h2", "h3"}, 2);
  ASSERT_EQ(q.Take(0), 0u);
  q.Report(0, 0, HostFailed("tunnel closed"));
  ASSERT_EQ(q.Take(1), 0u);
  q.Report(1, 0, HostFailed("engine gone"));
  EXPECT_EQ(q.reports()[0].status, TrialStatus::kExhausted);
  EXPECT_EQ(q.reports()[0].reason,
            "gave up after 2 attempts (h1: tunnel closed; h2: engine gone)");
  EXPECT_TRUE(q.Finished());
  EXPECT_TRUE(q.host_up(2));
}

TEST(WorkQueue, NoHostLeftLeavesTheRestNotRun) {
  WorkQueue q(3, {"only"}, 3);
  ASSERT_EQ(q.Take(0), 0u);
  q.Report(0, 0, HostFailed("gone"));
  EXPECT_TRUE(q.Finished());
  for (const TrialReport& r : q.reports()) {
    EXPECT_EQ(r.status, TrialStatus::kNotRun);
    EXPECT_NE(r.reason.find("no host left in the pool"), std::string::npos) << r.reason;
  }
}

TEST(WorkQueue, StopKeepsRunningTrialsAndAbandonsThePending) {
  WorkQueue q(3, {"local"}, 3);
  ASSERT_EQ(q.Take(0), 0u);
  q.Stop("interrupted (Ctrl-C)");
  EXPECT_FALSE(q.Take(0).has_value());
  EXPECT_FALSE(q.Finished());
  q.Report(0, 0, {AttemptResult::Kind::kCancelled, "", "interrupted"});
  EXPECT_TRUE(q.Finished());
  EXPECT_EQ(q.reports()[0].status, TrialStatus::kNotRun);
  EXPECT_EQ(q.reports()[0].attempts, 0);  // a cancelled attempt does not count
  EXPECT_EQ(q.reports()[2].reason, "interrupted (Ctrl-C)");
}

// A fake host: runs trials instantly (with a short sleep so slots overlap), fails as a host after
// `fail_after` trials (then for every later call), records concurrency and what ran where.
class FakeHost final : public HostWorker {
 public:
  FakeHost(std::string name, int slots, int fail_after)
      : name_(std::move(name)), slots_(slots), fail_after_(fail_after) {}
  std::string name() const override { return name_; }
  int slots() const override { return slots_; }
  AttemptResult Run(const PlannedTrial& trial, int /*attempt*/) override {
    const int now = ++in_flight_;
    {
      std::lock_guard lock(mu_);
      max_in_flight_ = std::max(max_in_flight_, now);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    AttemptResult r;
    {
      std::lock_guard lock(mu_);
      if (fail_after_ >= 0 && started_ >= fail_after_) {
        r = HostFailed("engine of " + name_ + " stopped answering");
      } else {
        ++started_;
        completed_.push_back(trial.id);
        r = Completed();
      }
    }
    --in_flight_;
    return r;
  }
  std::vector<std::string> completed() {
    std::lock_guard lock(mu_);
    return completed_;
  }
  int max_in_flight() {
    std::lock_guard lock(mu_);
    return max_in_flight_;
  }

 private:
  std::string name_;
  int slots_;
  int fail_after_;
  std::atomic<int> in_flight_{0};
  std::mutex mu_;
  int started_ = 0;
  int max_in_flight_ = 0;
  std::vector<std::string> completed_;
};

class CountingObserver final : public ScheduleObserver {
 public:
  void OnHostDown(const std::string& host, const std::string& /*reason*/) override {
    down.push_back(host);
  }
  void OnExhausted(const PlannedTrial& t, const std::string& /*reason*/) override {
    exhausted.push_back(t.id);
  }
  std::vector<std::string> down;
  std::vector<std::string> exhausted;
};

std::vector<PlannedTrial> Trials(int n) {
  std::vector<PlannedTrial> out;
  for (int i = 0; i < n; ++i) {
    PlannedTrial t;
    t.id = "t" + std::to_string(i);
    out.push_back(t);
  }
  return out;
}

TEST(RunSchedule, SpreadsOverEverySlotWithinEachHostsLimit) {
  FakeHost a("a", 2, -1), b("b", 3, -1);
  CountingObserver obs;
  auto reports = RunSchedule(Trials(40), {&a, &b}, {}, obs);
  ASSERT_EQ(reports.size(), 40u);
  for (const TrialReport& r : reports) EXPECT_EQ(r.status, TrialStatus::kCompleted);
  EXPECT_EQ(a.completed().size() + b.completed().size(), 40u);
  EXPECT_GT(a.completed().size(), 0u);
  EXPECT_GT(b.completed().size(), 0u);
  EXPECT_LE(a.max_in_flight(), 2);
  EXPECT_LE(b.max_in_flight(), 3);
}

TEST(RunSchedule, AHostFailingMidRunHasItsTrialsRequeuedAndEveryTrialRunsOnce) {
  FakeHost good("good", 1, -1), bad("bad", 2, 3);  // bad completes 3 trials, then fails
  CountingObserver obs;
  auto reports = RunSchedule(Trials(20), {&good, &bad}, {.max_attempts = 3}, obs);
  std::multiset<std::string> ran;
  for (const auto& id : good.completed()) ran.insert(id);
  for (const auto& id : bad.completed()) ran.insert(id);
  ASSERT_EQ(ran.size(), 20u);
  for (const PlannedTrial& t : Trials(20)) EXPECT_EQ(ran.count(t.id), 1u) << t.id;
  for (const TrialReport& r : reports) EXPECT_EQ(r.status, TrialStatus::kCompleted);
  EXPECT_EQ(obs.down, std::vector<std::string>{"bad"});
  EXPECT_TRUE(obs.exhausted.empty());
  EXPECT_EQ(bad.completed().size(), 3u);
}

TEST(RunSchedule, WhenEveryHostFailsTrialsAreExhaustedOrNotRunAndNothingHangs) {
  FakeHost x("x", 1, 0), y("y", 1, 0);
  CountingObserver obs;
  auto reports = RunSchedule(Trials(5), {&x, &y}, {.max_attempts = 2}, obs);
  int exhausted = 0, not_run = 0;
  for (const TrialReport& r : reports) {
    if (r.status == TrialStatus::kExhausted) ++exhausted;
    if (r.status == TrialStatus::kNotRun) ++not_run;
  }
  EXPECT_EQ(exhausted + not_run, 5);
  EXPECT_EQ(static_cast<int>(obs.exhausted.size()), exhausted);
  EXPECT_EQ(obs.down.size(), 2u);
}

TEST(RunSchedule, InterruptStopsHandingOutWork) {
  FakeHost a("a", 1, -1);
  std::atomic<bool> interrupted{true};
  CountingObserver obs;
  auto reports = RunSchedule(Trials(4), {&a}, {.max_attempts = 3, .interrupted = &interrupted}, obs);
  EXPECT_TRUE(a.completed().empty());
  for (const TrialReport& r : reports) EXPECT_EQ(r.status, TrialStatus::kNotRun);
}

}  // namespace
}  // namespace swarmbox::experiment
