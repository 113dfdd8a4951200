// Three swarmbox-raft-node processes over the bus on loopback (integration):
//   a leader is elected (event=leader_elected agreed by all three), a proposal commits on all
//   three (event=mission_state with the same index and state everywhere), the leader is
//   SIGKILLed, the other two elect a new leader (failover time printed: kill -> first
//   leader_elected of another node seen in a survivor's output), the survivors commit more, and
//   the killed node restarted on the same --data-dir re-applies its log (Raft §5.3, durable WAL)
//   and catches up to the survivors' committed index with the same states.
// One instance per middleware and one mixing both, each on its own DDS domain. Waits add up to < 180 s (the
// TIMEOUT). The scenario steps are tests/support/raft_scenario.hpp's, shared with
// tests/agent/app/agent_raft_test.cpp (the same scenario with swarmbox-agent processes).
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "support/files.hpp"
#include "support/logged_child.hpp"
#include "support/raft_scenario.hpp"

namespace swarmbox::raft_service {
namespace {

using namespace std::chrono_literals;
using swarmbox::testing::LeaderKillScenario;
using swarmbox::testing::LoggedChild;
using swarmbox::testing::Members;

const std::vector<std::string> kMembers = {"scout_1", "scout_2", "lifter"};

struct Backend {
  std::string name;  // "cyclonedds", "fastdds", or "mixed" (nodes alternate the two)
  int domain;
};
void PrintTo(const Backend& b, std::ostream* os) { *os << b.name << "@domain" << b.domain; }

std::string MiddlewareOf(const Backend& b, const std::string& node) {
  if (b.name != "mixed") return b.name;
  // scout_1 and lifter on Cyclone DDS, scout_2 on Fast DDS: both speak standard RTPS.
  return node == "scout_2" ? "fastdds" : "cyclonedds";
}

class RaftCluster : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override {
    // The nodes link Debian's Fast DDS 2.9, whose DataWriter deletion trips ASan's
    // new_delete_type_mismatch (the library's bug, see tests/bus/sanitizer_options.cpp). Only read
    // by ASan builds; an ASAN_OPTIONS already in the environment wins.
    setenv("ASAN_OPTIONS", "new_delete_type_mismatch=0", 0);
    root_ = swarmbox::testing::MakeTempDir("swarmbox_raft_cluster_");
    ASSERT_FALSE(root_.empty());
  }
  void TearDown() override {
    if (!HasFailure() && !root_.empty()) std::filesystem::remove_all(root_);  // keep on failure
  }

  std::unique_ptr<LoggedChild> Launch(const std::string& name, const std::string& log_name) {
    std::string members;
    for (const std::string& m : kMembers) members += (members.empty() ? "" : ",") + m;
    std::vector<std::string> argv = {
        SWARMBOX_RAFT_NODE_BIN, "--name", name, "--members", members, "--data-dir", root_ + "/" + name,
        "--domain", std::to_string(GetParam().domain), "--interface", "lo", "--middleware",
        MiddlewareOf(GetParam(), name), "--seed", "7", "--propose-every-ms", "300",
        // Ends on its own even if ctest SIGKILLs this test at its
        // TIMEOUT (no destructor would reap the nodes then).
        "--duration-s", "170"};
    auto child = std::make_unique<LoggedChild>(argv, root_ + "/" + log_name);
    EXPECT_TRUE(child->running()) << "spawning " << argv[0] << ": " << child->spawn_error();
    return child;
  }

  std::string root_;
};

TEST_P(RaftCluster, LeaderKillFailsOverAndRestartedNodeCatchesUp) {
  Members nodes;
  for (const std::string& n : kMembers) nodes[n] = Launch(n, n + ".log");
  LeaderKillScenario scenario(nodes, "[cluster " + GetParam().name + "]", 10ms);

  // 1. A leader everyone agrees on (the latest leader_elected of each node).
  ASSERT_TRUE(scenario.AgreeOnLeader(40s));
  // 2. A proposal of the leader commits on all three: same index, same state.
  ASSERT_TRUE(scenario.CommitOnAll(20s));
  // 3. SIGKILL the leader; the survivors elect another one.
  ASSERT_TRUE(scenario.KillLeaderAndFailOver(20s));
  // 4. The new leader commits more on both survivors.
  ASSERT_TRUE(scenario.SurvivorsCommitMore(20s));
  // 5. Restart the killed node on its data dir: it re-applies its durable log (before it hears
  // from any leader) and catches up with the survivors' states.
  const std::string leader = scenario.leader();
  ASSERT_TRUE(
      scenario.RestartLeaderAndCatchUp([&] { return Launch(leader, leader + ".restarted.log"); }, 40s));

  // 6. Clean shutdown on SIGTERM.
  for (auto& [name, c] : nodes) c->Signal(SIGTERM);
  for (auto& [name, c] : nodes) EXPECT_EQ(c->Wait(10s), 0) << name << "\n" << c->ReadLog();
}

INSTANTIATE_TEST_SUITE_P(Middleware, RaftCluster,
                         ::testing::Values(Backend{"cyclonedds", 182}, Backend{"fastdds", 183},
                                           Backend{"mixed", 188}),
                         [](const ::testing::TestParamInfo<Backend>& i) { return i.param.name; });

}  // namespace
}  // namespace swarmbox::raft_service
