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
#include "swarmbox/raft/conf_change.hpp"

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
  // Re-recorded for #19 (commit "mission: a single view never confirms a victim"): the random
  // sightings of these runs confirmed pairs of sightings before; they now stay candidates until
  // a leader decides, so those victim_confirmed lines (and their mission_state lines) are gone.
  // The operator's ConfirmVictim still confirms. The lines before that were the f0a2131 driver's.
  for (const Golden& g : {Golden{3, 2, 23, 0x3349b9b9d6715892ULL}, Golden{5, 1, 53, 0x1db6cc02b8e2b421ULL},
                          Golden{5, 2, 55, 0x48f394438689e0a4ULL}}) {
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

// Membership (conf_change.hpp): 9 nodes, 3 voters and 6 learners through the hostile network and
// faults, the drivers' lost-voter replacement and a random change at the leader every ~0.5 s:
// besides the safety properties, every node's configuration after each index is the same, a
// leader is a voter, one change at a time, and every commit is held by a majority of voters.
TEST(ClusterSim, MembershipChangesStaySafeUnderFaults) {
  int conf_changes = 0;
  std::uint64_t commits = 0;
  for (std::uint64_t seed = 80000; seed < 80300; ++seed) {
    const SimReport r = RunSimulation(MembershipSimConfig(9, 3, seed));
    ASSERT_TRUE(r.ok()) << r.violations.front();
    conf_changes += r.conf_changes;
    commits += r.max_commit;
  }
  EXPECT_GT(conf_changes, 300 * 5);  // the changes did happen (else the checks are vacuous)
  EXPECT_GT(commits, 300u * 20);
  for (std::uint64_t seed = 81000; seed < 81100; ++seed) {
    SimConfig c = MembershipSimConfig(12, 5, seed);
    c.machine = SimMachine::kEntryLog;  // the tap replays the whole log across changes too
    const SimReport r = RunSimulation(c);
    ASSERT_TRUE(r.ok()) << r.violations.front();
  }
}

// The swarm at scale (swarmbox-bench raft scenario=swarm_n100): 100 nodes, 5 voters, 95 learners
// on the radio; the leader crashes at 5 s, a voter at 11 s. A new leader is elected, the lost
// voter is replaced, and the leader never queues more than a handful of frames at once.
TEST(ClusterSim, HundredDronesFailOverAndReplaceALostVoter) {
  for (std::uint64_t seed = 90000; seed < 90010; ++seed) {
    SimConfig c;
    c.nodes = 100;
    c.voters = 5;
    c.seed = seed;
    c.duration_s = 20;
    c.propose_interval_s = 0.2;
    c.leader_crash_at_s = {5};
    c.voter_crash_at_s = {11};
    const SimReport r = RunSimulation(c);
    ASSERT_TRUE(r.ok()) << r.violations.front();
    EXPECT_EQ(r.failover_ms.size(), 1u) << seed;
    ASSERT_EQ(r.replacement_ms.size(), 1u) << seed;
    EXPECT_LT(r.replacement_ms[0], 4000) << seed;  // voter_lost 1.5 s, then two commits
    EXPECT_LE(r.leader_burst_max, 20) << seed;     // 4 voters + ceil(95 / 20) learners per tick
    EXPECT_LT(r.leader_messages / 20, 300u) << seed;
  }
}

// The replacement policy step by step, with the event lines every node prints when it applies a
// change: a voter goes silent, the leader removes it, promotes a learner, adds the lost node back
// as a learner; restarted, it follows the log as a learner with the same configuration.
TEST(ClusterSim, LostVoterIsReplacedAndEveryNodeLogsTheChanges) {
  SimConfig c;
  c.nodes = 12;
  c.voters = 3;
  c.seed = 3;
  c.record_events = true;
  c.snapshot_every_entries = 1000;  // a node that catches up by snapshot prints no change lines
  ClusterSim sim(c);
  int leader = sim.RunUntilLeader(5);
  ASSERT_GE(leader, 0);
  sim.RunFor(3);
  leader = sim.Leader();
  ASSERT_LT(leader, 3);  // n1..n3 vote
  const int victim = leader == 0 ? 1 : 0;
  const std::string name = sim.Name(victim);
  const NodeId id = sim.driver(leader)->IdOf(name);
  sim.Crash(victim);
  sim.RunFor(6);
  leader = sim.Leader();
  ASSERT_GE(leader, 0);
  const ConfState conf = sim.driver(leader)->conf_state();
  EXPECT_EQ(conf.voters.size(), 3u);
  EXPECT_FALSE(IsVoter(conf, id));
  EXPECT_TRUE(IsLearner(conf, id));
  auto count = [&](const std::string& what) {
    const auto& ev = sim.report().events;
    return std::count_if(ev.begin(), ev.end(), [&](const std::string& l) { return l.find(what) != std::string::npos; });
  };
  EXPECT_EQ(count("event=raft_conf_change op=remove node=" + name + " "), 11);
  EXPECT_EQ(count("event=raft_conf_change op=promote"), 11);
  EXPECT_EQ(count("event=raft_conf_change op=add_learner node=" + name + " "), 11);
  // The configuration is durable: a learner that applied the changes has them again at once
  // after a restart, from its storage alone (the WAL's replay of the committed entries).
  int learner = -1;
  for (int i = 3; i < sim.size() && learner < 0; ++i) {
    if (sim.alive(i) && sim.driver(i)->raft().is_learner()) learner = i;
  }
  ASSERT_GE(learner, 0);
  const ConfState before = sim.driver(learner)->conf_state();
  sim.Crash(learner);
  sim.Restart(learner);
  EXPECT_EQ(sim.driver(learner)->conf_state(), before);
  sim.Restart(victim);
  sim.RunFor(4);
  ASSERT_TRUE(sim.report().ok()) << sim.report().violations.front();
  EXPECT_EQ(sim.driver(victim)->conf_state(), sim.driver(sim.Leader())->conf_state());
  EXPECT_TRUE(sim.driver(victim)->raft().is_learner());
  EXPECT_GE(sim.driver(victim)->raft().log().committed() + 10, sim.driver(sim.Leader())->raft().log().committed());
}

// A voting set of every node is the classic cluster: the same run, event for event.
TEST(ClusterSim, VotingSetOfEveryNodeChangesNothing) {
  SimConfig c = HostileSimConfig(5, 4242);
  c.record_events = true;
  const SimReport all = RunSimulation(c);
  c.voters = 5;
  const SimReport five = RunSimulation(c);
  ASSERT_TRUE(all.ok() && five.ok());
  EXPECT_EQ(all.events, five.events);
  EXPECT_EQ(all.messages_sent, five.messages_sent);
  EXPECT_EQ(all.conf_changes, 0);
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
