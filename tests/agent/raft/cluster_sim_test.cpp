// The seeded cluster simulator (agent/raft/sim): thousands of runs of 3, 5 and 7 nodes with
// delay, jitter, loss, duplication, reordering, partitions and crash/restart, checking the Raft
// safety properties (Raft §5.2 Figure 3) after every step. A failure prints the seed; replay it
// with RunSimulation(cfg) and the same cfg.seed.
#include "swarmbox/raft/sim/cluster_sim.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace swarmbox::raft::sim {
namespace {

SimConfig Hostile(int nodes, std::uint64_t seed) {
  SimConfig c;
  c.nodes = nodes;
  c.seed = seed;
  c.duration_s = 12;
  c.net.delay_ms = 30;
  c.net.jitter_ms = 25;
  c.net.loss = 0.1;
  c.net.duplicate = 0.05;
  c.net.reorder = 0.1;
  c.net.reorder_ms = 200;
  c.faults.crash_mean_interval_s = 2;
  c.faults.down_min_s = 0.2;
  c.faults.down_max_s = 3;
  c.faults.partition_mean_interval_s = 3;
  c.faults.partition_min_s = 0.3;
  c.faults.partition_max_s = 3;
  c.snapshot_every_entries = 8;
  c.propose_interval_s = 0.05;
  return c;
}

void RunSeeds(int nodes, std::uint64_t first_seed, int count) {
  int leader_terms = 0;
  std::uint64_t commits = 0, snapshots = 0;
  for (int k = 0; k < count; ++k) {
    const SimReport r = RunSimulation(Hostile(nodes, first_seed + static_cast<std::uint64_t>(k)));
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

TEST(ClusterSim, ThreeNodesStaySafeUnderFaults) { RunSeeds(3, 1000, 700); }
TEST(ClusterSim, FiveNodesStaySafeUnderFaults) { RunSeeds(5, 2000, 500); }
TEST(ClusterSim, SevenNodesStaySafeUnderFaults) { RunSeeds(7, 3000, 300); }

}  // namespace
}  // namespace swarmbox::raft::sim
