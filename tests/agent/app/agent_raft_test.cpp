// Raft hosted by swarmbox-agent (integration): swarmbox-physics with three drones and three
// swarmbox-agent processes with --members on loopback (sim and mesh on their own DDS domains,
// 200-215). A leader is elected (event=leader_elected agreed by all three), a proposal of the
// --propose-every-ms loop commits on all three (event=mission_state, same index and state), the
// leader agent is SIGKILLed (the physics server marks its drone lost and goes on), the other two
// elect a new leader (failover printed: kill -> first leader_elected of another drone in a
// survivor's output) and commit more, and the killed agent restarted on the same --raft-dir
// re-applies its WAL (Raft §5.3: at least the pre-kill committed index, before hearing from a
// leader) and catches up to the survivors with the same states (State Machine Safety, §5.4.3).
// The scenario steps 1-5 are tests/support/raft_scenario.hpp's, shared with
// tests/agent/raft_service/raft_cluster_test.cpp. Waits add up to < 240 s (the TIMEOUT).
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "support/files.hpp"
#include "support/logged_child.hpp"
#include "support/raft_scenario.hpp"
#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::agent::testing {
namespace {

using namespace std::chrono_literals;
using swarmbox::testing::Events;
using swarmbox::testing::LeaderKillScenario;
using swarmbox::testing::LoggedChild;
using swarmbox::testing::MakeTempDir;
using swarmbox::testing::Members;
using swarmbox::testing::WaitUntil;

const std::vector<std::string> kNames = {"drone_1", "drone_2", "drone_3"};
const std::vector<std::string> kStarts = {"0,0,0", "4,0,0", "0,4,0"};
constexpr auto kPoll = 20ms;

// Sim and mesh domains of a run: 200-215, a pair chosen by process id (parallel runs differ) and
// moved on at every run of the fixture (--gtest_repeat: no stale endpoints of the last run).
int g_run = 0;
int SimDomain() { return 200 + static_cast<int>((getpid() + g_run) % 8) * 2; }

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

  std::unique_ptr<LoggedChild> StartPhysics() {
    std::vector<std::string> argv = {SWARMBOX_PHYSICS_BIN, "--world",
                                     SWARMBOX_TRIALS_DIR "/worlds/open_field.yaml", "--rtf", "1", "--domain",
                                     std::to_string(SimDomain()),
                                     // Ends on its own even if ctest SIGKILLs this test at its TIMEOUT.
                                     "--max-sim-time", "230", "--no-cameras", "--seed", "7", "--truth", ""};
    for (std::size_t i = 0; i < kNames.size(); ++i) {
      argv.push_back("--drone");
      argv.push_back(kNames[i] + ":x500:" + kStarts[i]);
    }
    auto child = std::make_unique<LoggedChild>(argv, root_ + "/physics.log");
    EXPECT_TRUE(child->running()) << "spawning " << argv[0] << ": " << child->spawn_error();
    return child;
  }

  std::unique_ptr<LoggedChild> StartAgent(std::size_t i, const std::string& log_name) {
    std::string members;
    for (const std::string& m : kNames) members += (members.empty() ? "" : ",") + m;
    std::vector<std::string> argv = {
        SWARMBOX_AGENT_BIN, "--name", kNames[i], "--airframe", SWARMBOX_TRIALS_DIR "/airframes/x500.yaml",
        "--sim-domain", std::to_string(SimDomain()), "--mesh-domain", std::to_string(SimDomain() + 1),
        "--start", kStarts[i], "--plan", "takeoff:3,hover:1000", "--members", members,
        "--raft-dir", root_ + "/raft_" + kNames[i], "--seed", "7", "--propose-every-ms", "300",
        "--sample-timeout", "120", "--stall-timeout", "20"};
    auto child = std::make_unique<LoggedChild>(argv, root_ + "/" + log_name);
    EXPECT_TRUE(child->running()) << "spawning " << argv[0] << ": " << child->spawn_error();
    return child;
  }

  std::string root_;
};

TEST_F(AgentRaft, LeaderAgentKillFailsOverAndRestartedAgentCatchesUpFromItsWal) {
  std::unique_ptr<LoggedChild> physics = StartPhysics();
  Members agents;
  for (std::size_t i = 0; i < kNames.size(); ++i) agents[kNames[i]] = StartAgent(i, kNames[i] + ".log");
  LeaderKillScenario scenario(agents, "[agent raft]", kPoll);
  scenario.AlsoDump(physics.get());

  // 0. All three are in lockstep with the physics server (each has taken off): only then is
  // the drone of the agent killed below known to the server, which then marks it lost.
  ASSERT_TRUE(WaitUntil(
      [&] {
        for (const auto& [name, c] : agents) {
          if (Events(c->ReadLog(), "takeoff").empty()) return false;
        }
        return true;
      },
      60s, kPoll))
      << scenario.DumpLogs();

  // 1. A leader all three agree on (each one's latest leader_elected).
  ASSERT_TRUE(scenario.AgreeOnLeader(60s));
  const std::string leader = scenario.leader();

  // 2. A proposal commits on all three: same index, same state.
  ASSERT_TRUE(scenario.CommitOnAll(30s));
  // Raft events carry the agents' simulated time: the physics server is stepping them.
  for (const auto& [name, c] : agents) {
    const auto ev = Events(c->ReadLog(), "mission_state");
    ASSERT_FALSE(ev.empty());
    EXPECT_GT(std::stod(FindField(ev.back(), "t").value_or("0")), 0.0) << name;
  }

  // 3. SIGKILL the leader agent; the physics server marks its drone lost and goes on; the
  // survivors elect another leader.
  ASSERT_TRUE(scenario.KillLeaderAndFailOver(30s));
  ASSERT_TRUE(WaitUntil(
      [&] {
        for (const LogfmtFields& f : Events(physics->ReadLog(), "drone_lost")) {
          if (FindField(f, "a") == leader) return true;
        }
        return false;
      },
      20s, kPoll))
      << physics->ReadLog();
  EXPECT_TRUE(physics->running()) << physics->ReadLog();

  // 4. The new leader commits more on both survivors.
  ASSERT_TRUE(scenario.SurvivorsCommitMore(30s));

  // 5. Restart the killed agent on its --raft-dir: it re-applies its durable log (before it hears
  // from any leader) and catches up with the survivors' states.
  const std::size_t leader_index = static_cast<std::size_t>(leader.back() - '1');
  ASSERT_TRUE(scenario.RestartLeaderAndCatchUp(
      [&] { return StartAgent(leader_index, leader + ".restarted.log"); }, 40s));

  // 6. Nobody crashed or stopped its Raft node on the way.
  for (const auto& [name, c] : agents) {
    EXPECT_TRUE(c->running()) << name << "\n" << c->ReadLog();
    EXPECT_TRUE(Events(c->ReadLog(), "raft_stopped").empty()) << name;
  }
  // 7. Shutdown: SIGTERM ends each agent with 0 after event=stopped (it leaves without the DDS
  // goodbye, main.cpp LeaveNow).
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
