// RawNode, one rule per test, in the spirit of etcd-io/raft's raft_paper_test.go. Each test names
// the rule of the Raft paper (Raft §x) or Ongaro's thesis (thesis §x) it checks.
#include "swarmbox/raft/raw_node.hpp"

#include <gtest/gtest.h>

#include <set>

#include "raft_test_util.hpp"

namespace swarmbox::raft {
namespace {

using testing::Drain;
using testing::Ent;
using testing::Filter;
using testing::MakeConfig;
using testing::MakeNode;
using testing::Msg;
using testing::Network;

// Raft §5.1: a server that sees a higher term updates its term and reverts to follower.
TEST(RawNodePaper, AnyRoleStepsDownOnHigherTerm) {
  for (Role start : {Role::kFollower, Role::kCandidate, Role::kLeader}) {
    RawNode n = MakeNode(MakeConfig(1, 3));
    if (start != Role::kFollower) {
      n.Campaign();
      Drain(n);
      if (start == Role::kLeader) {
        Message r = Msg(MessageType::kVoteResp, 2, 1, n.term());
        ASSERT_TRUE(n.Step(r).ok());
        Drain(n);
      }
    }
    ASSERT_EQ(n.role(), start);
    Message m = Msg(MessageType::kApp, 2, 1, 5);
    ASSERT_TRUE(n.Step(m).ok());
    EXPECT_EQ(n.term(), 5u) << RoleName(start);
    EXPECT_EQ(n.role(), Role::kFollower) << RoleName(start);
    EXPECT_EQ(n.lead(), 2u) << RoleName(start);
  }
}

// Raft §5.1: a request with a stale term is rejected (ignored, without PreVote/CheckQuorum).
TEST(RawNodePaper, StaleTermMessageIsIgnored) {
  RawNode n = MakeNode(MakeConfig(1, 3), PersistentState{HardState{4, 0, 0}, {}, {}});
  Message m = Msg(MessageType::kApp, 2, 1, 3);
  m.entries.push_back(Ent(1, 3));
  ASSERT_TRUE(n.Step(m).ok());
  EXPECT_TRUE(Drain(n).empty());
  EXPECT_EQ(n.log().last_index(), 0u);
}

// Raft §5.2: servers start as followers.
TEST(RawNodePaper, StartsAsFollower) {
  RawNode n = MakeNode(MakeConfig(1, 3));
  EXPECT_EQ(n.role(), Role::kFollower);
  EXPECT_EQ(n.lead(), kNoNode);
}

// Raft §5.2: a leader sends periodic heartbeats to every follower.
TEST(RawNodePaper, LeaderBroadcastsHeartbeats) {
  Network net(3);
  net.Campaign(1);
  ASSERT_EQ(net[1].role(), Role::kLeader);
  net[1].Tick();  // heartbeat_ticks = 1
  auto hb = Filter(Drain(net[1]), MessageType::kHeartbeat);
  ASSERT_EQ(hb.size(), 2u);
  std::set<NodeId> to{hb[0].to, hb[1].to};
  EXPECT_EQ(to, (std::set<NodeId>{2, 3}));
  EXPECT_EQ(hb[0].term, net[1].term());
}

// Raft §5.2: a follower that hears nothing for an election timeout increments its term, votes for
// itself and requests votes from every other server.
TEST(RawNodePaper, FollowerStartsElectionOnTimeout) {
  RawNode n = MakeNode(MakeConfig(1, 3));
  Drain(n);
  const std::uint64_t term = n.term();
  for (int i = 0; i < 2 * 10; ++i) n.Tick();
  EXPECT_EQ(n.role(), Role::kCandidate);
  EXPECT_EQ(n.term(), term + 1);
  EXPECT_EQ(n.vote(), 1u);
  Ready rd = n.GetReady();
  // The vote is durable before the requests leave (Figure 2: persist before responding/sending).
  ASSERT_TRUE(rd.hard_state.has_value());
  EXPECT_EQ(rd.hard_state->vote, 1u);
  EXPECT_EQ(Filter(rd.messages, MessageType::kVote).size(), 2u);
  n.Advance(rd);
}

// Raft §5.2: election timeouts are chosen randomly from a fixed interval [et, 2et).
TEST(RawNodePaper, ElectionTimeoutIsRandomisedInRange) {
  std::set<int> seen;
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    RawNode n = MakeNode(MakeConfig(1, 3, false, false, seed));
    const int t = n.randomized_election_timeout();
    EXPECT_GE(t, 10);
    EXPECT_LT(t, 20);
    seen.insert(t);
  }
  EXPECT_GT(seen.size(), 5u);
}

// Raft §5.2: a candidate wins with votes from a majority, loses on a majority of rejections.
TEST(RawNodePaper, CandidateNeedsMajorityOfVotes) {
  struct Case {
    int size;
    std::map<NodeId, bool> votes;
    Role want;
  };
  const std::vector<Case> cases = {
      {1, {}, Role::kLeader},
      {3, {{2, true}}, Role::kLeader},
      {3, {{2, false}}, Role::kCandidate},
      {3, {{2, false}, {3, false}}, Role::kFollower},
      {5, {{2, true}}, Role::kCandidate},
      {5, {{2, true}, {3, true}}, Role::kLeader},
      {5, {{2, false}, {3, false}}, Role::kCandidate},
      {5, {{2, false}, {3, false}, {4, false}}, Role::kFollower},
  };
  for (const Case& c : cases) {
    RawNode n = MakeNode(MakeConfig(1, c.size));
    n.Campaign();
    Drain(n);
    for (auto [from, granted] : c.votes) {
      Message r = Msg(MessageType::kVoteResp, from, 1, n.term());
      r.reject = !granted;
      ASSERT_TRUE(n.Step(r).ok());
      Drain(n);
    }
    EXPECT_EQ(n.role(), c.want) << "size " << c.size << " votes " << c.votes.size();
  }
}

// Raft §5.2: each server votes for at most one candidate in a term, first come first served.
TEST(RawNodePaper, FollowerVotesOncePerTerm) {
  RawNode n = MakeNode(MakeConfig(1, 3));
  Drain(n);
  Message v2 = Msg(MessageType::kVote, 2, 1, 2);
  ASSERT_TRUE(n.Step(v2).ok());
  auto r = Filter(Drain(n), MessageType::kVoteResp);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_FALSE(r[0].reject);
  Message v3 = Msg(MessageType::kVote, 3, 1, 2);
  ASSERT_TRUE(n.Step(v3).ok());
  r = Filter(Drain(n), MessageType::kVoteResp);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_TRUE(r[0].reject);
  // The same candidate asking again (a retry) gets the same answer.
  ASSERT_TRUE(n.Step(v2).ok());
  r = Filter(Drain(n), MessageType::kVoteResp);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_FALSE(r[0].reject);
}

// Raft §5.2: a candidate that receives an AppendEntries from a leader of its term steps down.
TEST(RawNodePaper, CandidateFollowsLeaderOfSameTerm) {
  RawNode n = MakeNode(MakeConfig(1, 3));
  n.Campaign();
  Drain(n);
  Message m = Msg(MessageType::kApp, 2, 1, n.term());
  ASSERT_TRUE(n.Step(m).ok());
  EXPECT_EQ(n.role(), Role::kFollower);
  EXPECT_EQ(n.lead(), 2u);
}

// Raft §5.4.1: a voter denies its vote to a candidate whose log is less up-to-date.
TEST(RawNodePaper, VoteDeniedToCandidateWithStaleLog) {
  PersistentState st{HardState{2, 0, 0}, {}, {Ent(1, 1), Ent(2, 2)}};
  struct Case {
    std::uint64_t index, log_term;
    bool reject;
  };
  for (const Case& c : std::vector<Case>{{2, 1, true}, {1, 2, true}, {2, 2, false}, {3, 2, false},
                                         {1, 3, false}}) {
    RawNode n = MakeNode(MakeConfig(1, 3), st);
    Message v = Msg(MessageType::kVote, 2, 1, 3);
    v.index = c.index;
    v.log_term = c.log_term;
    ASSERT_TRUE(n.Step(v).ok());
    auto r = Filter(Drain(n), MessageType::kVoteResp);
    ASSERT_EQ(r.size(), 1u);
    EXPECT_EQ(r[0].reject, c.reject) << c.index << "/" << c.log_term;
  }
}

// Raft §8: a new leader appends a no-op entry of its term, and replicates it.
TEST(RawNodePaper, NewLeaderAppendsNoop) {
  Network net(3);
  net.Campaign(1);
  ASSERT_EQ(net[1].role(), Role::kLeader);
  const Entry& e = net[1].log().At(net[1].log().last_index());
  EXPECT_EQ(e.type, EntryType::kEmpty);
  EXPECT_EQ(e.term, net[1].term());
  EXPECT_EQ(net[1].log().committed(), e.index);
  EXPECT_EQ(net[2].log().committed(), e.index);
}

// Raft §5.3: an entry is committed once the leader has replicated it on a majority; followers
// learn the commit index from later AppendEntries.
TEST(RawNodePaper, LeaderCommitsOnMajorityAndFollowersLearnIt) {
  Network net(5);
  net.Campaign(1);
  net.Isolate(4);
  net.Isolate(5);
  net.Propose(1, "cmd");
  const std::uint64_t idx = net[1].log().last_index();
  EXPECT_EQ(net[1].log().committed(), idx);  // 1, 2, 3 of 5
  EXPECT_EQ(net[2].log().committed(), idx);
  EXPECT_EQ(net[4].log().committed(), idx - 1);
  net.Isolate(3);
  net.Propose(1, "cmd2");  // only 1 and 2 have it: no majority
  EXPECT_EQ(net[1].log().committed(), idx);
}

// Raft §5.4.2 (Figure 8): a leader never commits an entry of an earlier term by counting
// replicas; it is committed indirectly once an entry of the current term is.
TEST(RawNodePaper, OldTermEntryIsNotCommittedByCounting) {
  // Leader 1 of term 3 holds an uncommitted entry of term 2 at index 2.
  PersistentState st{HardState{3, 1, 1}, {}, {Ent(1, 1), Ent(2, 2)}};
  RawNode n = MakeNode(MakeConfig(1, 3), st);
  n.Campaign();  // term 4
  Drain(n);
  Message grant = Msg(MessageType::kVoteResp, 2, 1, n.term());
  ASSERT_TRUE(n.Step(grant).ok());
  ASSERT_EQ(n.role(), Role::kLeader);
  Drain(n);
  // Follower 2 acknowledges index 2 only (not the new no-op at 3).
  Message ack = Msg(MessageType::kAppResp, 2, 1, n.term());
  ack.index = 2;
  ASSERT_TRUE(n.Step(ack).ok());
  EXPECT_EQ(n.log().committed(), 1u);
  // Once the no-op of the current term is on a majority, index 2 is committed with it.
  ack.index = 3;
  ASSERT_TRUE(n.Step(ack).ok());
  EXPECT_EQ(n.log().committed(), 3u);
}

// Raft §5.3: a follower rejects an AppendEntries whose previous entry it lacks; the leader backs
// off nextIndex and retries until the logs match, then the follower's conflicting entries go.
TEST(RawNodePaper, LeaderRepairsDivergentFollowerLog) {
  Network net(3);
  net.Campaign(1);
  net.Propose(1, "a");
  // Node 3 is cut off while 1 appends more; then 3 comes back.
  net.Isolate(3);
  net.Propose(1, "b");
  net.Propose(1, "c");
  net.Recover();
  net.TickAll(1);  // heartbeat -> response -> append of the missing entries
  EXPECT_EQ(net[3].log().last_index(), net[1].log().last_index());
  EXPECT_EQ(net[3].log().committed(), net[1].log().committed());
  for (std::uint64_t i = 1; i <= net[1].log().last_index(); ++i) {
    EXPECT_EQ(net[3].log().At(i), net[1].log().At(i)) << i;
  }
}

// Raft §5.3 Log Matching: a follower with extra uncommitted entries of an old term has them
// replaced by the leader's.
TEST(RawNodePaper, FollowerConflictingEntriesAreOverwritten) {
  PersistentState st{HardState{2, 0, 1}, {}, {Ent(1, 1), Ent(2, 2, "x"), Ent(3, 2, "y")}};
  RawNode f = MakeNode(MakeConfig(2, 3), st);
  Message app = Msg(MessageType::kApp, 1, 2, 3);
  app.index = 1;
  app.log_term = 1;
  app.entries = {Ent(2, 3, "z")};
  app.commit = 2;
  ASSERT_TRUE(f.Step(app).ok());
  EXPECT_EQ(f.log().last_index(), 2u);
  EXPECT_EQ(f.log().At(2).term, 3u);
  EXPECT_EQ(f.log().committed(), 2u);
  Ready rd = f.GetReady();
  ASSERT_EQ(rd.entries.size(), 1u);  // index 2 must be rewritten in storage
  EXPECT_EQ(rd.entries[0].index, 2u);
  f.Advance(rd);
}

// thesis §9.6: a pre-candidate does not increment its term, so a node cut off from the cluster
// keeps its term and cannot force a healthy leader to step down when it comes back.
TEST(RawNodePaper, PreVoteKeepsTermWhileIsolated) {
  Network net(3, /*pre_vote=*/true, /*check_quorum=*/true);
  net.Campaign(1);
  ASSERT_EQ(net[1].role(), Role::kLeader);
  const std::uint64_t term = net[1].term();
  net.Isolate(3);
  net.TickAll(100);  // node 3 times out repeatedly
  EXPECT_EQ(net[3].term(), term);
  EXPECT_EQ(net[3].role(), Role::kPreCandidate);
  net.Recover();
  net.TickAll(3);
  EXPECT_EQ(net[1].role(), Role::kLeader);
  EXPECT_EQ(net[1].term(), term);
  EXPECT_EQ(net[3].role(), Role::kFollower);
  EXPECT_EQ(net[3].lead(), 1u);
}

// Without PreVote the same isolation makes the returning node's higher term depose the leader:
// the behaviour PreVote exists to prevent (contrast with the test above).
TEST(RawNodePaper, WithoutPreVoteIsolatedNodeInflatesTerm) {
  Network net(3);
  net.Campaign(1);
  const std::uint64_t term = net[1].term();
  net.Isolate(3);
  net.TickAll(100);
  EXPECT_GT(net[3].term(), term + 2);
}

// thesis §9.6: a pre-vote is granted for a future term without changing the voter's term or vote.
TEST(RawNodePaper, PreVoteGrantDoesNotBindVoter) {
  RawNode n = MakeNode(MakeConfig(1, 3, /*pre_vote=*/true));
  Drain(n);
  Message pv = Msg(MessageType::kPreVote, 2, 1, 5);
  ASSERT_TRUE(n.Step(pv).ok());
  auto r = Filter(Drain(n), MessageType::kPreVoteResp);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_FALSE(r[0].reject);
  EXPECT_EQ(r[0].term, 5u);
  EXPECT_EQ(n.term(), 1u);
  EXPECT_EQ(n.vote(), kNoNode);
}

// thesis §6.2 CheckQuorum: a leader that does not hear from a majority for an election timeout
// steps down.
TEST(RawNodePaper, CheckQuorumLeaderStepsDownWithoutMajority) {
  Network net(3, true, true);
  net.Campaign(1);
  ASSERT_EQ(net[1].role(), Role::kLeader);
  net.Isolate(1);
  net.Tick(1, 10);
  EXPECT_EQ(net[1].role(), Role::kLeader);  // first check: peers were active
  net.Tick(1, 10);
  EXPECT_EQ(net[1].role(), Role::kFollower);
}

// thesis §4.2.3: a server that heard from a current leader within the minimum election timeout
// ignores RequestVote (the leader lease): a disruptive candidate cannot take over.
TEST(RawNodePaper, VotesIgnoredWithinLeaderLease) {
  Network net(3, false, true);
  net.Campaign(1);
  const std::uint64_t term = net[1].term();
  Message v = Msg(MessageType::kVote, 3, 2, term + 1);
  v.index = net[2].log().last_index();
  v.log_term = net[2].log().last_term();
  ASSERT_TRUE(net[2].Step(v).ok());
  EXPECT_TRUE(Drain(net[2]).empty());
  EXPECT_EQ(net[2].term(), term);
}

// A follower forwards proposals to its leader; with no leader they are dropped with a reason.
TEST(RawNodePaper, ProposalsForwardedToLeaderOrDropped) {
  RawNode alone = MakeNode(MakeConfig(2, 3));
  Status s = alone.Propose(Bytes{1});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code(), ErrorCode::kUnavailable);
  EXPECT_NE(s.error().message().find("no known leader"), std::string::npos);

  Network net(3);
  net.Campaign(1);
  net.Propose(2, "from-follower");
  const Entry& e = net[1].log().At(net[1].log().last_index());
  EXPECT_EQ(std::string(e.data.begin(), e.data.end()), "from-follower");
  EXPECT_EQ(net[3].log().committed(), e.index);
}

// Raft §7: a follower whose needed entries were compacted away gets the snapshot.
TEST(RawNodePaper, LaggingFollowerReceivesSnapshot) {
  Network net(3);
  net.Campaign(1);
  net.Isolate(3);
  for (int i = 0; i < 5; ++i) net.Propose(1, "x");
  const std::uint64_t applied = net[1].log().applied();
  ASSERT_TRUE(net[1].Compact(applied, Bytes{42}).ok());
  net.Recover();
  net.TickAll(1);
  EXPECT_EQ(net[3].log().snapshot_index(), applied);
  EXPECT_EQ(net[3].snapshot().data, Bytes{42});
  EXPECT_EQ(net[3].log().committed(), net[1].log().committed());
  EXPECT_EQ(net[1].progress(3)->match, net[1].log().last_index());
}

// Raft §7: a received snapshot is handed to the application in Ready, before later entries.
TEST(RawNodePaper, ReadyCarriesReceivedSnapshot) {
  RawNode f = MakeNode(MakeConfig(2, 3));
  Drain(f);
  Message snap = Msg(MessageType::kSnap, 1, 2, 3);
  snap.snapshot = Snapshot{7, 2, Bytes{9}};
  ASSERT_TRUE(f.Step(snap).ok());
  Ready rd = f.GetReady();
  EXPECT_EQ(rd.snapshot.index, 7u);
  EXPECT_TRUE(rd.committed_entries.empty());
  auto resp = Filter(rd.messages, MessageType::kAppResp);
  ASSERT_EQ(resp.size(), 1u);
  EXPECT_EQ(resp[0].index, 7u);
  f.Advance(rd);
  EXPECT_FALSE(f.HasReady());
}

// A stale leader (e.g. after a partition) learns the new term from followers' replies and steps
// down (etcd-io/raft, needed with PreVote).
TEST(RawNodePaper, StaleLeaderStepsDownOnReplyWithHigherTerm) {
  Network net(3, true, true);
  net.Campaign(1);
  net.Isolate(1);
  net.TickAll(40);  // 2 and 3 elect a new leader
  ASSERT_TRUE(net[2].role() == Role::kLeader || net[3].role() == Role::kLeader);
  ASSERT_NE(net[1].role(), Role::kLeader);  // CheckQuorum already deposed it
  const std::uint64_t new_term = std::max(net[2].term(), net[3].term());
  // Even a leader that did not step down learns the term from the reply to its heartbeat.
  RawNode old = MakeNode(MakeConfig(1, 3));
  old.Campaign();
  Drain(old);
  ASSERT_TRUE(old.Step(Msg(MessageType::kVoteResp, 2, 1, old.term())).ok());
  ASSERT_EQ(old.role(), Role::kLeader);
  Drain(old);
  ASSERT_TRUE(old.Step(Msg(MessageType::kAppResp, 2, 1, new_term + 5)).ok());
  EXPECT_EQ(old.role(), Role::kFollower);
  EXPECT_EQ(old.term(), new_term + 5);
}

// Restart: a node rebuilt from its durable state keeps term, vote and log, and re-applies the
// committed entries after its snapshot.
TEST(RawNodePaper, RestartRestoresDurableState) {
  PersistentState st{HardState{5, 2, 3}, Snapshot{1, 1, {}}, {Ent(2, 1), Ent(3, 4), Ent(4, 5)}};
  RawNode n = MakeNode(MakeConfig(1, 3), st);
  EXPECT_EQ(n.term(), 5u);
  EXPECT_EQ(n.vote(), 2u);
  EXPECT_EQ(n.log().last_index(), 4u);
  Ready rd = n.GetReady();
  EXPECT_FALSE(rd.hard_state.has_value());
  ASSERT_EQ(rd.committed_entries.size(), 2u);
  EXPECT_EQ(rd.committed_entries[0].index, 2u);
  n.Advance(rd);
  // Still the same vote in term 5: a different candidate is refused.
  Message v = Msg(MessageType::kVote, 3, 1, 5);
  v.index = 10;
  v.log_term = 5;
  ASSERT_TRUE(n.Step(v).ok());
  auto r = Filter(Drain(n), MessageType::kVoteResp);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_TRUE(r[0].reject);
}

TEST(RawNodeConfig, InvalidConfigurationsAreRejectedWithReason) {
  Config c = MakeConfig(4, 3);
  auto n = RawNode::Create(c);
  ASSERT_FALSE(n.ok());
  EXPECT_NE(n.error().message().find("not among the voters"), std::string::npos);
  c = MakeConfig(1, 3);
  c.election_ticks = 1;
  n = RawNode::Create(c);
  ASSERT_FALSE(n.ok());
  EXPECT_NE(n.error().message().find("must be greater than heartbeat_ticks"), std::string::npos);
  n = RawNode::Create(MakeConfig(1, 3), PersistentState{HardState{1, 0, 9}, {}, {Ent(1, 1)}});
  ASSERT_FALSE(n.ok());
  EXPECT_NE(n.error().message().find("beyond the last stored index"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::raft
