#include "support/raft_scenario.hpp"

#include <csignal>
#include <cstdio>
#include <optional>
#include <set>
#include <sstream>

namespace swarmbox::testing {

using SteadyClock = std::chrono::steady_clock;

std::vector<LogfmtFields> Events(const std::string& log, std::string_view event) {
  std::vector<LogfmtFields> out;
  std::istringstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    LogfmtFields f = ParseLogfmt(line);
    if (FindField(f, "event") == std::string(event)) out.push_back(std::move(f));
  }
  return out;
}

std::uint64_t U64(const LogfmtFields& f, std::string_view key) {
  return std::stoull(FindField(f, key).value_or("0"));
}

StateByIndex MissionStates(const std::string& log) {
  StateByIndex out;
  for (const LogfmtFields& f : Events(log, "mission_state")) {
    if (FindField(f, "from") == std::string("snapshot")) continue;
    const std::uint64_t index = U64(f, "index");
    const std::string state = FindField(f, "state").value_or("");
    auto [it, inserted] = out.emplace(index, state);
    EXPECT_EQ(it->second, state) << "index " << index << " applied with two states";
  }
  return out;
}

std::uint64_t HighestCommonIndex(const std::vector<StateByIndex>& maps) {
  std::uint64_t best = 0;
  for (const auto& [index, state] : maps.front()) {
    bool everywhere = true;
    for (const auto& m : maps) {
      auto it = m.find(index);
      if (it == m.end() || it->second != state) everywhere = false;
    }
    if (everywhere) best = index;
  }
  return best;
}

LeaderKillScenario::LeaderKillScenario(Members& members, std::string label, std::chrono::milliseconds poll)
    : members_(members), label_(std::move(label)), poll_(poll) {}

std::string LeaderKillScenario::DumpLogs() const {
  std::string s;
  for (const LoggedChild* c : others_) s += "---- " + c->log_path() + "\n" + c->ReadLog();
  for (const auto& [name, c] : members_) s += "---- " + c->log_path() + "\n" + c->ReadLog();
  return s;
}

::testing::AssertionResult LeaderKillScenario::AgreeOnLeader(std::chrono::milliseconds timeout) {
  const bool elected = WaitUntil(
      [&] {
        std::set<std::string> seen;
        for (const auto& [name, c] : members_) {
          auto ev = Events(c->ReadLog(), "leader_elected");
          if (ev.empty()) return false;
          seen.insert(FindField(ev.back(), "leader").value_or("") + "@" +
                      FindField(ev.back(), "term").value_or(""));
        }
        if (seen.size() != 1) return false;
        leader_ = seen.begin()->substr(0, seen.begin()->find('@'));
        return !leader_.empty();
      },
      timeout, poll_);
  if (!elected) return ::testing::AssertionFailure() << "no leader agreed by all members\n" << DumpLogs();
  std::printf("%s leader=%s\n", label_.c_str(), leader_.c_str());
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult LeaderKillScenario::CommitOnAll(std::chrono::milliseconds timeout) {
  const bool committed = WaitUntil(
      [&] {
        std::vector<StateByIndex> maps;
        for (const auto& [name, c] : members_) maps.push_back(MissionStates(c->ReadLog()));
        before_kill_ = HighestCommonIndex(maps);
        return before_kill_ > 0;
      },
      timeout, poll_);
  if (!committed) return ::testing::AssertionFailure() << "nothing committed on all members\n" << DumpLogs();
  std::printf("%s committed on all three: index=%llu\n", label_.c_str(),
              static_cast<unsigned long long>(before_kill_));
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult LeaderKillScenario::KillLeaderAndFailOver(std::chrono::milliseconds timeout) {
  survivors_.clear();
  std::map<std::string, std::size_t> elections_before;
  for (const auto& [name, c] : members_) {
    if (name == leader_) continue;
    survivors_.push_back(name);
    elections_before[name] = Events(c->ReadLog(), "leader_elected").size();
  }
  LoggedChild& killed = *members_.at(leader_);
  const auto killed_at = SteadyClock::now();
  killed.Signal(SIGKILL);
  if (const int code = killed.Wait(std::chrono::seconds(5)); code != 128 + SIGKILL) {
    return ::testing::AssertionFailure()
           << "the killed leader " << leader_ << " ended with " << code << ", not 128 + SIGKILL";
  }
  std::string new_leader;
  const bool failed_over = WaitUntil(
      [&] {
        for (const std::string& n : survivors_) {
          auto ev = Events(members_.at(n)->ReadLog(), "leader_elected");
          for (std::size_t i = elections_before[n]; i < ev.size(); ++i) {
            const std::string l = FindField(ev[i], "leader").value_or("");
            if (!l.empty() && l != leader_) {
              new_leader = l;
              return true;
            }
          }
        }
        return false;
      },
      timeout, poll_);
  const auto failover_ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(SteadyClock::now() - killed_at).count();
  if (!failed_over)
    return ::testing::AssertionFailure() << "no survivor elected a new leader\n" << DumpLogs();
  std::printf("%s failover_ms=%lld old_leader=%s new_leader=%s\n", label_.c_str(),
              static_cast<long long>(failover_ms), leader_.c_str(), new_leader.c_str());
  ::testing::Test::RecordProperty("failover_ms", std::to_string(failover_ms));
  EXPECT_NE(new_leader, leader_);
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult LeaderKillScenario::SurvivorsCommitMore(std::chrono::milliseconds timeout) {
  const bool committed = WaitUntil(
      [&] {
        std::vector<StateByIndex> maps;
        for (const std::string& n : survivors_) maps.push_back(MissionStates(members_.at(n)->ReadLog()));
        after_failover_ = HighestCommonIndex(maps);
        return after_failover_ > before_kill_;
      },
      timeout, poll_);
  if (!committed) {
    return ::testing::AssertionFailure()
           << "the survivors committed nothing above index " << before_kill_ << "\n"
           << DumpLogs();
  }
  std::printf("%s survivors committed up to index=%llu\n", label_.c_str(),
              static_cast<unsigned long long>(after_failover_));
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult LeaderKillScenario::RestartLeaderAndCatchUp(
    const std::function<std::unique_ptr<LoggedChild>()>& restart, std::chrono::milliseconds timeout) {
  const StateByIndex before_states = MissionStates(members_.at(leader_)->ReadLog());
  if (before_states.count(before_kill_) != 1) {
    return ::testing::AssertionFailure() << "the killed leader's log lacks index " << before_kill_;
  }
  members_[leader_] = restart();
  LoggedChild& restarted_child = *members_[leader_];
  std::uint64_t caught_up = 0;
  const bool caught = WaitUntil(
      [&] {
        const auto mine = MissionStates(restarted_child.ReadLog());
        if (mine.empty()) return false;
        caught_up = mine.rbegin()->first;
        return caught_up >= after_failover_;
      },
      timeout, poll_);
  if (!caught) {
    return ::testing::AssertionFailure()
           << "the restarted " << leader_ << " did not reach index " << after_failover_ << "\n"
           << DumpLogs();
  }
  const std::string restarted_log = restarted_child.ReadLog();
  const StateByIndex restarted = MissionStates(restarted_log);
  // What it had committed before the kill comes back from its own WAL (or snapshot), before it
  // hears from any leader.
  std::optional<std::size_t> reapplied_at, first_leader_at;
  {
    std::istringstream in(restarted_log);
    std::string line;
    for (std::size_t n = 0; std::getline(in, line); ++n) {
      const LogfmtFields f = ParseLogfmt(line);
      const auto event = FindField(f, "event");
      if (event == std::string("leader_elected") && !first_leader_at) first_leader_at = n;
      if (event != std::string("mission_state") || reapplied_at) continue;
      const bool snap = FindField(f, "from") == std::string("snapshot");
      if ((snap && U64(f, "index") >= before_kill_) ||
          (!snap && U64(f, "index") == before_kill_ &&
           FindField(f, "state") == before_states.at(before_kill_))) {
        reapplied_at = n;
      }
    }
  }
  if (!reapplied_at) {
    return ::testing::AssertionFailure() << "the restarted " << leader_ << " did not re-apply index "
                                         << before_kill_ << " from its own log\n"
                                         << restarted_log;
  }
  if (first_leader_at) {
    EXPECT_LT(*reapplied_at, *first_leader_at) << restarted_log;
  }
  // Same state at every index the survivors also applied (State Machine Safety, Raft §5.4.3).
  for (const std::string& n : survivors_) {
    const StateByIndex theirs = MissionStates(members_.at(n)->ReadLog());
    for (const auto& [index, state] : restarted) {
      if (auto it = theirs.find(index); it != theirs.end()) {
        EXPECT_EQ(state, it->second) << n << " differs at index " << index;
      }
    }
  }
  std::printf("%s restarted %s caught up to index=%llu (survivors had %llu)\n", label_.c_str(),
              leader_.c_str(), static_cast<unsigned long long>(caught_up),
              static_cast<unsigned long long>(after_failover_));
  return ::testing::AssertionSuccess();
}

}  // namespace swarmbox::testing
