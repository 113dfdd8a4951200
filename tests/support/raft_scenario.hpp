// The leader-kill scenario of a three-member Raft cluster whose members are separate programs
// printing their Raft events as logfmt lines (event=leader_elected leader= term=, event=
// mission_state index= state= [from=snapshot]). Shared by tests/agent/app/agent_raft_test.cpp
// (swarmbox-agent processes) and tests/agent/raft_service/raft_cluster_test.cpp (swarmbox-raft-node):
//
//   LeaderKillScenario s(members, "[cluster fastdds]", 10ms);
//   ASSERT_TRUE(s.AgreeOnLeader(40s));          // 1. one leader, agreed by all
//   ASSERT_TRUE(s.CommitOnAll(20s));            // 2. a proposal commits everywhere
//   ASSERT_TRUE(s.KillLeaderAndFailOver(20s));  // 3. SIGKILL it, the survivors elect another
//   ASSERT_TRUE(s.SurvivorsCommitMore(20s));    // 4.
//   ASSERT_TRUE(s.RestartLeaderAndCatchUp([&] { return Launch(s.leader()); }, 40s));  // 5.
//
// Every step polls the members' logs until it holds or its timeout passes, and fails with the
// logs of every member. Figures are printed with the label (leader, committed index, failover_ms,
// which is also recorded as a test property).
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "support/logged_child.hpp"
#include "support/wait_until.hpp"
#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::testing {

// The lines with event=`event` in a log, in order, as parsed logfmt fields.
std::vector<LogfmtFields> Events(const std::string& log, std::string_view event);

// A numeric field, 0 when absent.
std::uint64_t U64(const LogfmtFields& f, std::string_view key);

// Committed phase changes of one member: log index -> state. Re-applied entries repeat the same
// pair; a different state for one index is a safety violation and fails the test (EXPECT).
using StateByIndex = std::map<std::uint64_t, std::string>;
StateByIndex MissionStates(const std::string& log);

// The highest index present in every map with the same state, 0 when none.
std::uint64_t HighestCommonIndex(const std::vector<StateByIndex>& maps);

using Members = std::map<std::string, std::unique_ptr<LoggedChild>>;

class LeaderKillScenario {
 public:
  // `members` (name -> running program) stays owned by the test; `label` starts every printed
  // line; `poll` is the interval between two reads of the logs.
  LeaderKillScenario(Members& members, std::string label, std::chrono::milliseconds poll);

  // Another program whose log DumpLogs() shows first (e.g. the physics server).
  void AlsoDump(const LoggedChild* other) { others_.push_back(other); }
  // "---- <log path>" and the log of every program, for failure messages.
  std::string DumpLogs() const;

  // 1. A leader every member agrees on: the same leader and term in each one's latest
  // leader_elected.
  ::testing::AssertionResult AgreeOnLeader(std::chrono::milliseconds timeout);
  // 2. A proposal commits on all members: an index > 0 with the same state everywhere.
  ::testing::AssertionResult CommitOnAll(std::chrono::milliseconds timeout);
  // 3. SIGKILL the leader (it must end with 128 + SIGKILL within 5 s); a survivor then prints a
  // leader_elected naming another member. failover_ms = kill -> that line seen.
  ::testing::AssertionResult KillLeaderAndFailOver(std::chrono::milliseconds timeout);
  // 4. The survivors commit an index above the one of step 2, with the same states.
  ::testing::AssertionResult SurvivorsCommitMore(std::chrono::milliseconds timeout);
  // 5. Replaces the killed leader by `restart()` (same durable state directory) and waits until it
  // has applied at least the survivors' index of step 4. It must re-apply what it had committed
  // before the kill from its own WAL or snapshot before it hears of any leader (Raft §5.3: the log
  // survived the SIGKILL on disk), and agree with the survivors at every index both applied
  // (State Machine Safety, Raft §5.4.3).
  ::testing::AssertionResult RestartLeaderAndCatchUp(
      const std::function<std::unique_ptr<LoggedChild>()>& restart, std::chrono::milliseconds timeout);

  const std::string& leader() const { return leader_; }  // the first leader (step 1)
  const std::vector<std::string>& survivors() const { return survivors_; }
  std::uint64_t before_kill() const { return before_kill_; }

 private:
  Members& members_;
  std::string label_;
  std::chrono::milliseconds poll_;
  std::vector<const LoggedChild*> others_;
  std::string leader_;
  std::vector<std::string> survivors_;
  std::uint64_t before_kill_ = 0;
  std::uint64_t after_failover_ = 0;
};

}  // namespace swarmbox::testing
