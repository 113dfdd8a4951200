// The seeded cluster simulator (agent/raft/sim): thousands of runs of 3, 5 and 7 nodes with
// delay, jitter, loss, duplication, reordering, partitions and crash/restart, checking the Raft
// safety properties (Raft §5.2 Figure 3) after every step. A failure prints the seed; replay it
// with RunSimulation(cfg) and the same cfg.seed.
#include "swarmbox/raft/sim/cluster_sim.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "hostile_sim_config.hpp"

namespace swarmbox::raft::sim {
namespace {

void RunSeeds(int nodes, std::uint64_t first_seed, int count) {
  int leader_terms = 0;
  std::uint64_t commits = 0, snapshots = 0;
  for (int k = 0; k < count; ++k) {
    const SimReport r = RunSimulation(HostileSimConfig(nodes, first_seed + static_cast<std::uint64_t>(k)));
    ASSERT_TRUE(r.ok()) << r.violations.front();
    leader_terms += r.leader_terms;
    commits += r.max_commit;
    snapshots += r.snapshots_sent;
  }
  // The runs did make progress through the faults (otherwise safety would be vacuous).
  EXPECT_GT(leader_terms, count);
  EXPECT_GT(commits, static_cast<std::uint64_t>(count) * 20);
  EXPECT_GT(snapshots, 0u);
}

// 6,000 seeds in all, about half a minute on one core.
TEST(ClusterSim, ThreeNodesStaySafeUnderFaults) { RunSeeds(3, 10000, 3000); }
TEST(ClusterSim, FiveNodesStaySafeUnderFaults) { RunSeeds(5, 20000, 2000); }
TEST(ClusterSim, SevenNodesStaySafeUnderFaults) { RunSeeds(7, 30000, 1000); }

// Without PreVote and CheckQuorum (plain Raft §5) the cluster is just as safe.
TEST(ClusterSim, PlainRaftWithoutPreVoteOrCheckQuorumStaysSafe) {
  for (std::uint64_t seed = 40000; seed < 40300; ++seed) {
    SimConfig c = HostileSimConfig(5, seed);
    c.pre_vote = false;
    c.check_quorum = false;
    const SimReport r = RunSimulation(c);
    ASSERT_TRUE(r.ok()) << r.violations.front();
  }
}

// A seed replays exactly: what a failure report prints is enough to reproduce it.
TEST(ClusterSim, SameSeedSameRun) {
  SimConfig c = HostileSimConfig(5, 77);
  c.record_events = true;
  const SimReport a = RunSimulation(c);
  const SimReport b = RunSimulation(c);
  EXPECT_EQ(a.events, b.events);
  EXPECT_EQ(a.messages_sent, b.messages_sent);
  EXPECT_EQ(a.commit_ms, b.commit_ms);
  EXPECT_FALSE(a.events.empty());
  c.seed = 78;
  EXPECT_NE(RunSimulation(c).events, a.events);
}

}  // namespace
}  // namespace swarmbox::raft::sim
