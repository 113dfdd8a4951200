// Learners and one-at-a-time membership changes (conf_change.hpp, raw_node.hpp "Learners"), in
// the style of etcd-io/raft's raft_test.go learner and confchange tests. Each test names the rule
// (Raft thesis §4.1 single-server changes; etcd's learner semantics) it checks.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "raft_test_util.hpp"
#include "swarmbox/raft/conf_change.hpp"
#include "swarmbox/raft/message_codec.hpp"

namespace swarmbox::raft {
namespace {

using testing::Drain;
using testing::Filter;
using testing::MakeConfig;
using testing::MakeNode;
using testing::Msg;
using testing::Network;

TEST(ConfChange, EncodingRoundTripsAndRefusesGarbage) {
  for (ConfChangeOp op : {ConfChangeOp::kAddLearner, ConfChangeOp::kPromoteLearner, ConfChangeOp::kRemoveNode}) {
    const ConfChange c{op, 300};
    auto back = DecodeConfChange(EncodeConfChange(c));
    ASSERT_TRUE(back.ok()) << back.error().ToString();
    EXPECT_EQ(*back, c);
  }
  EXPECT_FALSE(DecodeConfChange(Bytes{}).ok());
  EXPECT_FALSE(DecodeConfChange(Bytes{9, 1}).ok());     // unknown op
  EXPECT_FALSE(DecodeConfChange(Bytes{1, 0}).ok());     // node 0
  EXPECT_FALSE(DecodeConfChange(Bytes{1, 1, 7}).ok());  // trailing byte
}

TEST(ConfChange, ApplyChangesOneNodeAndRefusesWhatDoesNotApply) {
  const ConfState c{{1, 2, 3}, {4}};
  auto promoted = ApplyConfChange(c, {ConfChangeOp::kPromoteLearner, 4});
  ASSERT_TRUE(promoted.ok());
  EXPECT_EQ(*promoted, (ConfState{{1, 2, 3, 4}, {}}));
  auto removed = ApplyConfChange(c, {ConfChangeOp::kRemoveNode, 2});
  ASSERT_TRUE(removed.ok());
  EXPECT_EQ(*removed, (ConfState{{1, 3}, {4}}));
  auto added = ApplyConfChange(c, {ConfChangeOp::kAddLearner, 9});
  ASSERT_TRUE(added.ok());
  EXPECT_EQ(*added, (ConfState{{1, 2, 3}, {4, 9}}));
  auto twice = ApplyConfChange(c, {ConfChangeOp::kAddLearner, 2});
  ASSERT_FALSE(twice.ok());
  EXPECT_NE(twice.error().message().find("already a voter"), std::string::npos);
  auto not_learner = ApplyConfChange(c, {ConfChangeOp::kPromoteLearner, 3});
  ASSERT_FALSE(not_learner.ok());
  EXPECT_NE(not_learner.error().message().find("already a voter"), std::string::npos);
  EXPECT_FALSE(ApplyConfChange(c, {ConfChangeOp::kRemoveNode, 8}).ok());
  auto last = ApplyConfChange(ConfState{{1}, {}}, {ConfChangeOp::kRemoveNode, 1});
  ASSERT_FALSE(last.ok());
  EXPECT_NE(last.error().message().find("the last voter"), std::string::npos);
}

// etcd learners: a learner never campaigns, however long it hears nothing.
TEST(RawNodeLearner, NeverCampaigns) {
  RawNode n = MakeNode(MakeConfig(4, 4, true, true, 1, 3));
  EXPECT_TRUE(n.is_learner());
  Drain(n);
  for (int i = 0; i < 100; ++i) {
    n.Tick();
    for (const Message& m : Drain(n)) {
      EXPECT_NE(m.type, MessageType::kPreVote);
      EXPECT_NE(m.type, MessageType::kVote);
    }
  }
  n.Campaign();
  EXPECT_EQ(n.role(), Role::kFollower);
  EXPECT_TRUE(Drain(n).empty());
}

// etcd learners: the leader never asks a learner for a vote, and learners' logs never make a
// quorum: with two of three voters cut off, four learners holding an entry do not commit it.
TEST(RawNodeLearner, IsNeverAskedToVoteAndNeverCountsForTheQuorum) {
  Network net(7, false, false, 3, 2);
  std::set<NodeId> asked;
  net.SetDrop([&](const Message& m) {
    if (m.type == MessageType::kVote) asked.insert(m.to);
    return false;
  });
  net.Campaign(1);
  ASSERT_EQ(net[1].role(), Role::kLeader);
  EXPECT_EQ(asked, (std::set<NodeId>{2, 3}));
  net.Recover();
  net.Isolate(2);
  net.Isolate(3);
  const std::uint64_t commit = net[1].log().committed();
  net.Propose(1, "sighting");
  net.Tick(1, 4);  // every learner's slot comes (period 2): they all hold the entry
  for (NodeId l = 4; l <= 7; ++l) EXPECT_EQ(net[l].log().last_index(), net[1].log().last_index()) << l;
  EXPECT_EQ(net[1].log().committed(), commit);
}

// Learner pacing: the leader serves each learner once per learner_heartbeat_ticks, in slots, so
// one tick never carries more than ceil(learners / period) learner messages; and the learner
// applies the log like a follower.
TEST(RawNodeLearner, IsServedInSlotsAndFollowsTheLog) {
  const int period = 10;
  Network net(43, false, false, 3, period);  // 3 voters, 40 learners
  net.Campaign(1);
  ASSERT_EQ(net[1].role(), Role::kLeader);
  net.Propose(1, "start");
  std::map<NodeId, int> served;
  for (int t = 0; t < period; ++t) {
    net[1].Tick();
    int to_learners = 0;
    for (const Message& m : Drain(net[1])) {
      if (m.to > 3) {
        ++to_learners;
        ++served[m.to];
      }
    }
    EXPECT_LE(to_learners, 4) << "tick " << t;
  }
  EXPECT_EQ(served.size(), 40u);
  for (const auto& [id, n] : served) EXPECT_EQ(n, 1) << id;
  net.Tick(1, 2 * period);
  for (NodeId l = 4; l <= 43; ++l) {
    EXPECT_EQ(net[l].log().committed(), net[1].log().committed()) << l;
    EXPECT_EQ(net[l].lead(), 1u) << l;
  }
}

// Thesis §4.1 (single-server changes) with etcd's rule: a change takes effect when applied, and a
// leader refuses a second change while one is in flight.
TEST(RawNodeConfChange, AppliesWhenAppliedAndOneAtATime) {
  Network net(5, false, false, 3, 1);
  net.Campaign(1);
  ASSERT_EQ(net[1].role(), Role::kLeader);
  ASSERT_TRUE(net[1].ProposeConfChange({ConfChangeOp::kPromoteLearner, 4}).ok());
  // Appended, not yet applied: the configuration is still the old one, and a second change waits.
  EXPECT_EQ(net[1].conf_state(), (ConfState{{1, 2, 3}, {4, 5}}));
  auto second = net[1].ProposeConfChange({ConfChangeOp::kPromoteLearner, 5});
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.error().code(), ErrorCode::kUnavailable);
  net.Send({});
  net.Tick(1, 2);
  for (NodeId id = 1; id <= 5; ++id) {
    EXPECT_EQ(net[id].conf_state(), (ConfState{{1, 2, 3, 4}, {5}})) << id;
  }
  EXPECT_TRUE(net[4].is_voter());
  EXPECT_TRUE(net[1].ProposeConfChange({ConfChangeOp::kRemoveNode, 2}).ok());
  net.Send({});
  net.Tick(1, 2);
  EXPECT_EQ(net[1].conf_state(), (ConfState{{1, 3, 4}, {5}}));
  EXPECT_EQ(net[1].progress(2), nullptr);
  EXPECT_EQ(net[1].invalid_conf_changes(), 0u);
}

// Thesis §4.1 (the single-server change bug, fixed by etcd's pendingConfIndex): a new leader
// proposes no change before it applied the no-op of its own term.
TEST(RawNodeConfChange, NewLeaderWaitsForItsNoopAndNeverRemovesItself) {
  Network net(4, false, false, 3, 1);
  net.Isolate(3);
  net.SetDrop([](const Message& m) { return m.type == MessageType::kAppResp; });
  net.Campaign(1);
  ASSERT_EQ(net[1].role(), Role::kLeader);
  auto early = net[1].ProposeConfChange({ConfChangeOp::kPromoteLearner, 4});
  ASSERT_FALSE(early.ok());
  EXPECT_EQ(early.error().code(), ErrorCode::kUnavailable);
  net.Recover();
  net.Tick(1, 2);
  ASSERT_GE(net[1].log().applied(), net[1].pending_conf_index());
  auto self = net[1].ProposeConfChange({ConfChangeOp::kRemoveNode, 1});
  ASSERT_FALSE(self.ok());
  EXPECT_EQ(self.error().code(), ErrorCode::kInvalidArgument);
  auto bad = net[1].ProposeConfChange({ConfChangeOp::kPromoteLearner, 2});
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_FALSE(net[2].ProposeConfChange({ConfChangeOp::kAddLearner, 9}).ok());  // not the leader
  EXPECT_TRUE(net[1].ProposeConfChange({ConfChangeOp::kPromoteLearner, 4}).ok());
}

// A removed voter stops counting at once: a 4-voter cluster that removes a dead voter commits
// with 2 of the remaining 3.
TEST(RawNodeConfChange, RemovingADeadVoterShrinksTheQuorum) {
  Network net(4);
  net.Campaign(1);
  ASSERT_EQ(net[1].role(), Role::kLeader);
  net.Isolate(4);
  ASSERT_TRUE(net[1].ProposeConfChange({ConfChangeOp::kRemoveNode, 4}).ok());
  net.Send({});
  net.Tick(1, 1);
  ASSERT_EQ(net[1].conf_state().voters, (std::vector<NodeId>{1, 2, 3}));
  net.Isolate(3);
  const std::uint64_t before = net[1].log().committed();
  net.Propose(1, "two of three");
  EXPECT_GT(net[1].log().committed(), before);
}

// The configuration is part of the snapshot (etcd's ConfState): compaction records it, a node
// restarted from it, or a follower given it, has the membership without the log before it.
TEST(RawNodeConfChange, ConfigurationTravelsInSnapshots) {
  Network net(4, false, false, 3, 1);
  net.Campaign(1);
  ASSERT_TRUE(net[1].ProposeConfChange({ConfChangeOp::kPromoteLearner, 4}).ok());
  net.Send({});
  net.Tick(1, 2);
  const ConfState conf{{1, 2, 3, 4}, {}};
  ASSERT_EQ(net[1].conf_state(), conf);
  ASSERT_TRUE(net[1].Compact(net[1].log().applied(), Bytes{1}).ok());
  EXPECT_EQ(net[1].snapshot().conf, conf);
  // A node restarted from that snapshot, configured with the old membership, takes the snapshot's.
  RawNode restarted = MakeNode(MakeConfig(2, 4, false, false, 1, 3),
                               PersistentState{HardState{net[1].term(), 0, net[1].snapshot().index},
                                               net[1].snapshot(), {}});
  EXPECT_EQ(restarted.conf_state(), conf);
  EXPECT_TRUE(restarted.is_voter());
  // The codec carries it.
  Message m = Msg(MessageType::kSnap, 1, 2, 3);
  m.snapshot = net[1].snapshot();
  auto back = DecodeMessage(EncodeMessage(m, 7), 7);
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(back->snapshot.conf, conf);
}

}  // namespace
}  // namespace swarmbox::raft
