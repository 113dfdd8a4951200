// The seeded cluster simulator (agent/raft/sim): thousands of runs of 3, 5 and 7 nodes with
// delay, jitter, loss, duplication, reordering, partitions and crash/restart, checking the Raft
// safety properties (Raft §5.2 Figure 3) and the committed-entries tap after every step, with
// the mission state machine and with the entry log. A failure prints the seed; replay it
// with RunSimulation(cfg) and the same cfg.seed.
#include "swarmbox/raft/sim/cluster_sim.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <span>
#include <string>
#include <vector>

#include "hostile_sim_config.hpp"

namespace swarmbox::raft::sim {
namespace {

void RunSeeds(int nodes, std::uint64_t first_seed, int count,
              SimMachine machine = SimMachine::kMission) {
  int leader_terms = 0;
  std::uint64_t commits = 0, snapshots = 0, tapped = 0;
  for (int k = 0; k < count; ++k) {
    SimConfig c = HostileSimConfig(nodes, first_seed + static_cast<std::uint64_t>(k));
    c.machine = machine;
    const SimReport r = RunSimulation(c);
    ASSERT_TRUE(r.ok()) << r.violations.front();
    leader_terms += r.leader_terms;
    commits += r.max_commit;
    snapshots += r.snapshots_sent;
    tapped += r.entries_tapped;
  }
  // The runs did make progress through the faults (otherwise safety would be vacuous).
  EXPECT_GT(leader_terms, count);
  EXPECT_GT(commits, static_cast<std::uint64_t>(count) * 20);
  EXPECT_GT(snapshots, 0u);
  EXPECT_GT(tapped, static_cast<std::uint64_t>(count) * 20);
}

// FNV-1a of the event lines, each followed by '\n'.
std::uint64_t HashLines(const std::vector<std::string>& lines) {
  std::string all;
  for (const auto& l : lines) all += l + "\n";
  return HashBytes(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(all.data()), all.size()));
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

// Any state machine: the entry log (EntryLogMachine) through the same hostile runs; besides the
// safety properties, every node's tap must yield the whole committed log from index 1 in every
// life of the node (the replay after a restart and after a snapshot from the leader).
TEST(ClusterSim, EntryLogMachineStaysSafeAndItsTapReplaysTheWholeLog) {
  RunSeeds(3, 50000, 300, SimMachine::kEntryLog);
  RunSeeds(5, 60000, 200, SimMachine::kEntryLog);
}

// The machine does not change consensus: the same seed gives the same messages and commits.
TEST(ClusterSim, StateMachineDoesNotChangeTheRaftRun) {
  for (std::uint64_t seed = 70000; seed < 70020; ++seed) {
    SimConfig c = HostileSimConfig(5, seed);
    const SimReport mission = RunSimulation(c);
    c.machine = SimMachine::kEntryLog;
    const SimReport log = RunSimulation(c);
    ASSERT_TRUE(mission.ok() && log.ok()) << seed;
    EXPECT_EQ(mission.messages_sent, log.messages_sent) << seed;
    EXPECT_EQ(mission.commit_ms, log.commit_ms) << seed;
    EXPECT_EQ(mission.max_commit, log.max_commit) << seed;
    EXPECT_EQ(mission.leader_terms, log.leader_terms) << seed;
  }
}

// The mission's event lines did not change when they moved behind MissionStateMachine: whole
// hostile runs (elections, restarts replaying the WAL, snapshots from the leader, victims
// confirmed, rescued) print exactly the lines the driver printed before (count and FNV-1a of
// every line; recorded with the driver of commit f0a2131).
TEST(ClusterSim, MissionEventsAreByteIdenticalToThePreStateMachineDriver) {
  struct Golden {
    int nodes;
    std::uint64_t seed;
    std::size_t lines;
    std::uint64_t hash;
  };
  for (const Golden& g : {Golden{3, 2, 44, 0xc5a6841928c165e6ULL}, Golden{5, 1, 82, 0x6a14ad6f0367f6caULL},
                          Golden{5, 2, 112, 0x17ce121ae210927dULL}}) {
    SimConfig c = HostileSimConfig(g.nodes, g.seed);
    c.record_events = true;
    const SimReport r = RunSimulation(c);
    ASSERT_TRUE(r.ok()) << r.violations.front();
    EXPECT_EQ(r.events.size(), g.lines) << "nodes=" << g.nodes << " seed=" << g.seed;
    EXPECT_EQ(HashLines(r.events), g.hash) << "nodes=" << g.nodes << " seed=" << g.seed;
    auto count = [&](const std::string& what) {
      return std::count_if(r.events.begin(), r.events.end(),
                           [&](const std::string& l) { return l.find(what) != std::string::npos; });
    };
    EXPECT_GT(count("event=mission_state"), 0);
    EXPECT_GT(count("event=victim_confirmed"), 0);
    EXPECT_GT(count("from=snapshot"), 0);
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
