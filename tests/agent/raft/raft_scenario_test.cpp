// Scripted scenarios on the cluster simulator (radio-like network: 100 ms +- 20 ms, 5% loss):
// leader crash, partitions, a stale leader rejoining, a cut-off follower rejoining, lost vote
// responses. Every step is also checked for the Raft safety properties by the simulator.
#include <gtest/gtest.h>

#include <map>

#include "swarmbox/raft/sim/cluster_sim.hpp"

namespace swarmbox::raft::sim {
namespace {

SimConfig Radio(int nodes, std::uint64_t seed) {
  SimConfig c;
  c.nodes = nodes;
  c.seed = seed;
  c.propose_interval_s = 0;  // the scenarios propose by hand
  return c;
}

std::uint64_t Term(const ClusterSim& sim, int node) { return sim.driver(node)->raft().term(); }

bool LogHolds(const ClusterSim& sim, int node, const std::string& reporter) {
  const RaftLog& log = sim.driver(node)->raft().log();
  for (std::uint64_t i = log.first_index(); i <= log.last_index(); ++i) {
    auto cmd = DecodeCommand(log.At(i).data);
    if (cmd && std::holds_alternative<ReportSighting>(*cmd) &&
        std::get<ReportSighting>(*cmd).reporter == reporter) {
      return true;
    }
  }
  return false;
}

void ExpectConverged(const ClusterSim& sim) {
  const int leader = sim.Leader();
  ASSERT_GE(leader, 0);
  for (int i = 0; i < sim.size(); ++i) {
    if (!sim.alive(i)) continue;
    EXPECT_EQ(sim.driver(i)->leader(), sim.Name(leader)) << sim.Name(i);
    EXPECT_EQ(sim.driver(i)->mission(), sim.driver(leader)->mission()) << sim.Name(i);
  }
}

// Given a healthy 5-drone cluster, when the leader crashes, then another drone leads within 2 s,
// the mission goes on, and the old leader rejoins as a follower with its state when restarted.
TEST(RaftScenario, LeaderCrashFailsOverAndOldLeaderRejoins) {
  ClusterSim sim(Radio(5, 11));
  const int old_leader = sim.RunUntilLeader(5);
  ASSERT_GE(old_leader, 0);
  ASSERT_TRUE(sim.Propose(old_leader, StartSearch{}).ok());
  sim.RunFor(1);
  sim.Crash(old_leader);
  const double t0 = sim.now_s();
  const int new_leader = sim.RunUntilLeader(5);
  ASSERT_GE(new_leader, 0);
  EXPECT_NE(new_leader, old_leader);
  EXPECT_LT(sim.now_s() - t0, 2.0);
  ASSERT_TRUE(sim.Propose(new_leader, ConfirmVictim{"n9", 3, 4}).ok());
  sim.RunFor(1);
  EXPECT_EQ(sim.driver(new_leader)->mission().victims().size(), 1u);
  sim.Restart(old_leader);
  EXPECT_EQ(sim.driver(old_leader)->mission().phase(), MissionPhase::kSearch);  // from its disk
  sim.RunFor(3);
  ASSERT_TRUE(sim.report().ok()) << sim.report().violations.front();
  ExpectConverged(sim);
  EXPECT_EQ(sim.Leader(), new_leader);
}

// Given a leader cut off with one follower (a minority), then the majority elects a new leader,
// the old one steps down (CheckQuorum, thesis §6.2), nothing the minority proposes commits, and
// after healing everyone follows the new leader with one state.
TEST(RaftScenario, MinorityPartitionLosesLeadershipAndCommitsNothing) {
  ClusterSim sim(Radio(5, 12));
  const int old_leader = sim.RunUntilLeader(5);
  ASSERT_GE(old_leader, 0);
  const int buddy = (old_leader + 1) % 5;
  std::vector<int> majority;
  for (int i = 0; i < 5; ++i) {
    if (i != old_leader && i != buddy) majority.push_back(i);
  }
  sim.Partition({{old_leader, buddy}, majority});
  ASSERT_TRUE(sim.Propose(old_leader, ReportSighting{"minority", 1, 1, 1, 0.95}).ok());
  const std::uint64_t minority_commit = sim.driver(old_leader)->raft().log().committed();
  sim.RunFor(4);
  const int new_leader = sim.Leader();
  ASSERT_GE(new_leader, 0);
  EXPECT_NE(new_leader, old_leader);
  EXPECT_NE(sim.driver(old_leader)->raft().role(), Role::kLeader);
  EXPECT_EQ(sim.driver(old_leader)->raft().log().committed(), minority_commit);
  ASSERT_TRUE(sim.Propose(new_leader, ReportSighting{"majority", 1, 50, 50, 0.95}).ok());
  sim.RunFor(1);
  sim.Heal();
  sim.RunFor(3);
  ASSERT_TRUE(sim.report().ok()) << sim.report().violations.front();
  ExpectConverged(sim);
  EXPECT_FALSE(LogHolds(sim, old_leader, "minority"));  // overwritten (Raft §5.3)
  EXPECT_TRUE(LogHolds(sim, old_leader, "majority"));
}

// Given a leader isolated alone, when it comes back after the others elected a new leader, then
// the stale leader learns the newer term and follows; the cluster is not disrupted.
TEST(RaftScenario, StaleLeaderRejoiningFollowsTheNewLeader) {
  ClusterSim sim(Radio(5, 13));
  const int old_leader = sim.RunUntilLeader(5);
  ASSERT_GE(old_leader, 0);
  std::vector<int> rest;
  for (int i = 0; i < 5; ++i) {
    if (i != old_leader) rest.push_back(i);
  }
  sim.Partition({{old_leader}, rest});
  sim.RunFor(5);
  const int new_leader = sim.Leader();
  ASSERT_GE(new_leader, 0);
  ASSERT_NE(new_leader, old_leader);
  const std::uint64_t term = Term(sim, new_leader);
  sim.Heal();
  sim.RunFor(3);
  ASSERT_TRUE(sim.report().ok()) << sim.report().violations.front();
  EXPECT_EQ(sim.Leader(), new_leader);
  EXPECT_EQ(Term(sim, new_leader), term);
  EXPECT_EQ(Term(sim, old_leader), term);
  ExpectConverged(sim);
}

// Given a follower cut off for 10 s (its election timer fires again and again), when it rejoins,
// then PreVote (thesis §9.6) has kept its term and the healthy leader stays in office.
TEST(RaftScenario, CutOffFollowerRejoiningDoesNotDeposeTheLeader) {
  ClusterSim sim(Radio(5, 14));
  const int leader = sim.RunUntilLeader(5);
  ASSERT_GE(leader, 0);
  const std::uint64_t term = Term(sim, leader);
  const int loner = (leader + 2) % 5;
  std::vector<int> rest;
  for (int i = 0; i < 5; ++i) {
    if (i != loner) rest.push_back(i);
  }
  sim.Partition({{loner}, rest});
  sim.RunFor(10);
  EXPECT_EQ(Term(sim, loner), term);
  sim.Heal();
  sim.RunFor(3);
  ASSERT_TRUE(sim.report().ok()) << sim.report().violations.front();
  EXPECT_EQ(sim.Leader(), leader);
  EXPECT_EQ(Term(sim, leader), term);
  ExpectConverged(sim);
}

// Given every vote response is lost, no leader can be elected (and, with PreVote, no term is
// wasted); once responses get through again, a leader is elected promptly.
TEST(RaftScenario, LostVoteResponsesBlockElectionUntilTheyArrive) {
  ClusterSim sim(Radio(3, 15));
  sim.SetDropFilter([](int, int, const Message& m) {
    return m.type == MessageType::kPreVoteResp || m.type == MessageType::kVoteResp;
  });
  sim.RunFor(5);
  EXPECT_EQ(sim.Leader(), -1);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(Term(sim, i), 1u) << i;
  sim.SetDropFilter(nullptr);
  EXPECT_GE(sim.RunUntilLeader(3), 0);
  ASSERT_TRUE(sim.report().ok()) << sim.report().violations.front();
}

// Given pre-votes succeed but every real vote response is lost, candidates keep starting new
// terms without a winner; when the votes get through, one leader emerges and safety held.
TEST(RaftScenario, LostRealVoteResponsesCostTermsNotSafety) {
  ClusterSim sim(Radio(5, 16));
  sim.SetDropFilter([](int, int, const Message& m) { return m.type == MessageType::kVoteResp; });
  sim.RunFor(5);
  EXPECT_EQ(sim.Leader(), -1);
  std::uint64_t max_term = 0;
  for (int i = 0; i < 5; ++i) max_term = std::max(max_term, Term(sim, i));
  EXPECT_GT(max_term, 2u);
  sim.SetDropFilter(nullptr);
  const int leader = sim.RunUntilLeader(5);
  ASSERT_GE(leader, 0);
  sim.RunFor(1);
  ASSERT_TRUE(sim.report().ok()) << sim.report().violations.front();
  ExpectConverged(sim);
}

// The checker is not vacuous: with storage wiped on restart (breaking Raft's durability
// assumption), it reports two leaders in a term, lost commits and diverging logs, each with the
// seed that reproduces it.
TEST(RaftScenario, CheckerCatchesBrokenDurability) {
  int caught = 0;
  std::map<std::string, int> kinds;
  for (std::uint64_t seed = 1; seed <= 100; ++seed) {
    SimConfig c;
    c.nodes = 3;
    c.seed = seed;
    c.duration_s = 10;
    c.net.delay_ms = 20;
    c.net.jitter_ms = 10;
    c.faults.crash_mean_interval_s = 1;
    c.faults.down_min_s = 0.1;
    c.faults.down_max_s = 0.5;
    c.faults.wipe_storage_on_restart = true;
    c.propose_interval_s = 0.05;
    const SimReport r = RunSimulation(c);
    if (!r.ok()) {
      ++caught;
      EXPECT_EQ(r.violations.front().rfind("seed=" + std::to_string(seed) + " nodes=3 t=", 0), 0u)
          << r.violations.front();
      for (const char* k : {"Election Safety: two leaders", "Leader Completeness", "Log Matching"}) {
        if (r.violations.front().find(k) != std::string::npos) ++kinds[k];
      }
    }
  }
  EXPECT_GT(caught, 20);
  EXPECT_GT(kinds["Election Safety: two leaders"], 0);
  EXPECT_GT(kinds["Leader Completeness"], 0);
  EXPECT_GT(kinds["Log Matching"], 0);
}

}  // namespace
}  // namespace swarmbox::raft::sim
