// Raft hosted by swarmbox-agent (integration): swarmbox-physics with three drones and three
// swarmbox-agent processes with --members on loopback (sim and mesh on their own DDS domains,
// 200-215). A leader is elected (event=leader_elected agreed by all three), a proposal of the
// --propose-every-ms loop commits on all three (event=mission_state, same index and state), the
// leader agent is SIGKILLed (the physics server marks its drone lost and goes on), the other two
// elect a new leader (failover printed: kill -> first leader_elected of another drone in a
// survivor's output) and commit more, and the killed agent restarted on the same --raft-dir
// re-applies its WAL (Raft §5.3: at least the pre-kill committed index, before hearing from a
// leader) and catches up to the survivors with the same states (State Machine Safety, §5.4.3).
// Process handling: process.hpp (this folder); the log helpers mirror
// tests/agent/mission/raft_cluster_test.cpp. Waits add up to < 240 s (the TIMEOUT).
#include <signal.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "process.hpp"
#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::agent::testing {
namespace {

using namespace std::chrono_literals;
using SteadyClock = std::chrono::steady_clock;

const std::vector<std::string> kNames = {"drone_1", "drone_2", "drone_3"};
const std::vector<std::string> kStarts = {"0,0,0", "4,0,0", "0,4,0"};

// Sim and mesh domains of a run: 200-215, a pair chosen by process id (parallel runs differ) and
// moved on at every run of the fixture (--gtest_repeat: no stale endpoints of the last run).
int g_run = 0;
int SimDomain() { return 200 + static_cast<int>((getpid() + g_run) % 8) * 2; }

// The events `event` in an agent's output, in order (flight and Raft events share stdout).
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

std::uint64_t U64(const LogfmtFields& f, std::string_view key) { return std::stoull(FindField(f, key).value_or("0")); }

// Committed phase changes: log index -> state (re-applied entries repeat the same pair; two
// states for one index would be a safety violation and fail the test).
std::map<std::uint64_t, std::string> MissionStates(const std::string& log) {
  std::map<std::uint64_t, std::string> out;
  for (const LogfmtFields& f : Events(log, "mission_state")) {
    if (FindField(f, "from") == std::string("snapshot")) continue;
    const std::uint64_t index = U64(f, "index");
    const std::string state = FindField(f, "state").value_or("");
    auto [it, inserted] = out.emplace(index, state);
    EXPECT_EQ(it->second, state) << "index " << index << " applied with two states";
  }
  return out;
}

// The highest index present in every map with the same state, 0 when none.
std::uint64_t HighestCommonIndex(const std::vector<std::map<std::uint64_t, std::string>>& maps) {
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

bool WaitUntil(const std::function<bool()>& pred, std::chrono::milliseconds timeout) {
  const auto deadline = SteadyClock::now() + timeout;
  while (SteadyClock::now() < deadline) {
    if (pred()) return true;
    std::this_thread::sleep_for(20ms);
  }
  return pred();
}

class AgentRaft : public ::testing::Test {
 protected:
  void SetUp() override {
    ++g_run;
    root_ = MakeTempDir("swarmbox_agent_raft_");
    ASSERT_FALSE(root_.empty());
  }
  void TearDown() override {
    if (!HasFailure() && !root_.empty()) std::filesystem::remove_all(root_);  // keep on failure
  }

  std::unique_ptr<Child> StartPhysics() {
    std::vector<std::string> argv = {SWARMBOX_PHYSICS_BIN, "--world", SWARMBOX_TRIALS_DIR "/worlds/open_field.yaml",
                                     "--rtf", "1", "--domain", std::to_string(SimDomain()),
                                     // Ends on its own even if ctest SIGKILLs this test at its TIMEOUT.
                                     "--max-sim-time", "230", "--no-cameras", "--seed", "7", "--truth", ""};
    for (std::size_t i = 0; i < kNames.size(); ++i) {
      argv.push_back("--drone");
      argv.push_back(kNames[i] + ":x500:" + kStarts[i]);
    }
    auto child = std::make_unique<Child>(argv, root_ + "/physics.log");
    EXPECT_TRUE(child->running()) << "spawning " << argv[0];
    return child;
  }

  std::unique_ptr<Child> StartAgent(std::size_t i, const std::string& log_name) {
    std::string members;
    for (const std::string& m : kNames) members += (members.empty() ? "" : ",") + m;
    std::vector<std::string> argv = {SWARMBOX_AGENT_BIN, "--name", kNames[i], "--airframe",
                                     SWARMBOX_TRIALS_DIR "/airframes/x500.yaml", "--sim-domain",
                                     std::to_string(SimDomain()), "--mesh-domain", std::to_string(SimDomain() + 1),
                                     "--start", kStarts[i], "--plan", "takeoff:3,hover:1000", "--members", members,
                                     "--raft-dir", root_ + "/raft_" + kNames[i], "--seed", "7",
                                     "--propose-every-ms", "300", "--sample-timeout", "120", "--stall-timeout", "20"};
    auto child = std::make_unique<Child>(argv, root_ + "/" + log_name);
    EXPECT_TRUE(child->running()) << "spawning " << argv[0];
    return child;
  }

  std::string DumpLogs(const std::map<std::string, std::unique_ptr<Child>>& agents, const Child& physics) const {
    std::string s = "---- " + physics.log_path() + "\n" + physics.ReadLog();
    for (const auto& [name, c] : agents) s += "---- " + c->log_path() + "\n" + c->ReadLog();
    return s;
  }

  std::string root_;
};

TEST_F(AgentRaft, LeaderAgentKillFailsOverAndRestartedAgentCatchesUpFromItsWal) {
  std::unique_ptr<Child> physics = StartPhysics();
  std::map<std::string, std::unique_ptr<Child>> agents;
  for (std::size_t i = 0; i < kNames.size(); ++i) agents[kNames[i]] = StartAgent(i, kNames[i] + ".log");

  // 0. All three are in lockstep with the physics server (each has taken off): only then is
  // the drone of the agent killed below known to the server, which then marks it lost.
  ASSERT_TRUE(WaitUntil([&] {
    for (const auto& [name, c] : agents) {
      if (Events(c->ReadLog(), "takeoff").empty()) return false;
    }
    return true;
  }, 60s)) << DumpLogs(agents, *physics);

  // 1. A leader all three agree on (each one's latest leader_elected).
  std::string leader;
  const bool elected = WaitUntil([&] {
    std::set<std::string> seen;
    for (const auto& [name, c] : agents) {
      auto ev = Events(c->ReadLog(), "leader_elected");
      if (ev.empty()) return false;
      seen.insert(FindField(ev.back(), "leader").value_or("") + "@" + FindField(ev.back(), "term").value_or(""));
    }
    if (seen.size() != 1) return false;
    leader = seen.begin()->substr(0, seen.begin()->find('@'));
    return !leader.empty();
  }, 60s);
  ASSERT_TRUE(elected) << DumpLogs(agents, *physics);
  std::printf("[agent raft] leader=%s\n", leader.c_str());

  // 2. A proposal commits on all three: same index, same state.
  std::uint64_t before_kill = 0;
  ASSERT_TRUE(WaitUntil([&] {
    std::vector<std::map<std::uint64_t, std::string>> maps;
    for (const auto& [name, c] : agents) maps.push_back(MissionStates(c->ReadLog()));
    before_kill = HighestCommonIndex(maps);
    return before_kill > 0;
  }, 30s)) << DumpLogs(agents, *physics);
  std::printf("[agent raft] committed on all three: index=%llu\n", static_cast<unsigned long long>(before_kill));
  // Raft events carry the agents' simulated time: the physics server is stepping them.
  for (const auto& [name, c] : agents) {
    const auto ev = Events(c->ReadLog(), "mission_state");
    ASSERT_FALSE(ev.empty());
    EXPECT_GT(std::stod(FindField(ev.back(), "t").value_or("0")), 0.0) << name;
  }

  // 3. SIGKILL the leader agent; the physics server marks its drone lost and goes on; the
  // survivors elect another leader.
  std::vector<std::string> survivors;
  std::map<std::string, std::size_t> elections_before;
  for (const std::string& n : kNames) {
    if (n == leader) continue;
    survivors.push_back(n);
    elections_before[n] = Events(agents[n]->ReadLog(), "leader_elected").size();
  }
  const auto killed_at = SteadyClock::now();
  agents[leader]->Signal(SIGKILL);
  ASSERT_EQ(agents[leader]->Wait(5s), 128 + SIGKILL);
  std::string new_leader;
  const bool failed_over = WaitUntil([&] {
    for (const std::string& n : survivors) {
      auto ev = Events(agents[n]->ReadLog(), "leader_elected");
      for (std::size_t i = elections_before[n]; i < ev.size(); ++i) {
        const std::string l = FindField(ev[i], "leader").value_or("");
        if (!l.empty() && l != leader) {
          new_leader = l;
          return true;
        }
      }
    }
    return false;
  }, 30s);
  const auto failover_ms = std::chrono::duration_cast<std::chrono::milliseconds>(SteadyClock::now() - killed_at).count();
  ASSERT_TRUE(failed_over) << DumpLogs(agents, *physics);
  std::printf("[agent raft] failover_ms=%lld old_leader=%s new_leader=%s\n", static_cast<long long>(failover_ms),
              leader.c_str(), new_leader.c_str());
  RecordProperty("failover_ms", std::to_string(failover_ms));
  EXPECT_NE(new_leader, leader);
  ASSERT_TRUE(WaitUntil([&] {
    for (const LogfmtFields& f : Events(physics->ReadLog(), "drone_lost")) {
      if (FindField(f, "a") == leader) return true;
    }
    return false;
  }, 20s)) << physics->ReadLog();
  EXPECT_TRUE(physics->running()) << physics->ReadLog();

  // 4. The new leader commits more on both survivors.
  std::uint64_t after_failover = 0;
  ASSERT_TRUE(WaitUntil([&] {
    std::vector<std::map<std::uint64_t, std::string>> maps;
    for (const std::string& n : survivors) maps.push_back(MissionStates(agents[n]->ReadLog()));
    after_failover = HighestCommonIndex(maps);
    return after_failover > before_kill;
  }, 30s)) << DumpLogs(agents, *physics);
  std::printf("[agent raft] survivors committed up to index=%llu\n", static_cast<unsigned long long>(after_failover));

  // 5. Restart the killed agent on its --raft-dir: it re-applies its durable log and catches up.
  const std::map<std::uint64_t, std::string> before_states = MissionStates(agents[leader]->ReadLog());
  ASSERT_EQ(before_states.count(before_kill), 1u);
  const std::size_t leader_index = static_cast<std::size_t>(leader.back() - '1');
  agents[leader] = StartAgent(leader_index, leader + ".restarted.log");
  std::uint64_t caught_up = 0;
  ASSERT_TRUE(WaitUntil([&] {
    const auto mine = MissionStates(agents[leader]->ReadLog());
    if (mine.empty()) return false;
    caught_up = mine.rbegin()->first;
    return caught_up >= after_failover;
  }, 40s)) << DumpLogs(agents, *physics);
  const std::string restarted_log = agents[leader]->ReadLog();
  const auto restarted = MissionStates(restarted_log);
  // What it had committed before the kill comes back from its own WAL (or snapshot), before it
  // hears from any leader: the log survived the SIGKILL on disk.
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
      if ((snap && U64(f, "index") >= before_kill) ||
          (!snap && U64(f, "index") == before_kill && FindField(f, "state") == before_states.at(before_kill))) {
        reapplied_at = n;
      }
    }
  }
  ASSERT_TRUE(reapplied_at.has_value()) << restarted_log;
  if (first_leader_at) {
    EXPECT_LT(*reapplied_at, *first_leader_at) << restarted_log;
  }
  for (const std::string& n : survivors) {
    const auto theirs = MissionStates(agents[n]->ReadLog());
    for (const auto& [index, state] : restarted) {
      if (auto it = theirs.find(index); it != theirs.end()) {
        EXPECT_EQ(state, it->second) << n << " differs at index " << index;
      }
    }
  }
  std::printf("[agent raft] restarted %s caught up to index=%llu (survivors had %llu)\n", leader.c_str(),
              static_cast<unsigned long long>(caught_up), static_cast<unsigned long long>(after_failover));

  // 6. Nobody crashed or stopped its Raft node on the way.
  for (const auto& [name, c] : agents) {
    EXPECT_TRUE(c->running()) << name << "\n" << c->ReadLog();
    EXPECT_TRUE(Events(c->ReadLog(), "raft_stopped").empty()) << name;
  }
  // 7. Clean shutdown: SIGTERM ends each agent with 0 (Raft service stopped before the mesh).
  for (auto& [name, c] : agents) c->Signal(SIGTERM);
  for (auto& [name, c] : agents) {
    EXPECT_EQ(c->Wait(10s), 0) << name << "\n" << c->ReadLog();
    EXPECT_FALSE(Events(c->ReadLog(), "stopped").empty()) << name;
  }
  physics->Signal(SIGTERM);
  EXPECT_EQ(physics->Wait(20s), 0) << physics->ReadLog();
}

}  // namespace
}  // namespace swarmbox::agent::testing
