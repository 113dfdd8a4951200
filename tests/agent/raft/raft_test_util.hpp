// Test helpers for RawNode: a tiny in-memory network in the style of etcd-io/raft's raft_test.go
// `network`: nodes, a persist-then-send Ready loop, and message filters.
#pragma once

#include <gtest/gtest.h>

#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <vector>

#include "swarmbox/raft/raw_node.hpp"

namespace swarmbox::raft::testing {

// Nodes 1..n; with voters > 0 only 1..voters vote and the others are learners.
inline Config MakeConfig(NodeId id, int n, bool pre_vote = false, bool check_quorum = false,
                         std::uint64_t seed = 1, int voters = 0) {
  Config c;
  c.id = id;
  for (int i = 1; i <= n; ++i) {
    (voters == 0 || i <= voters ? c.voters : c.learners).push_back(static_cast<NodeId>(i));
  }
  c.election_ticks = 10;
  c.heartbeat_ticks = 1;
  c.pre_vote = pre_vote;
  c.check_quorum = check_quorum;
  c.seed = seed;
  return c;
}

inline RawNode MakeNode(const Config& c, PersistentState st = {}) {
  auto n = RawNode::Create(c, std::move(st));
  EXPECT_TRUE(n.ok()) << (n.ok() ? "" : n.error().ToString());
  return std::move(*n);
}

// Drains a node's Ready: returns the messages it would send (storage is the node's own memory).
inline std::vector<Message> Drain(RawNode& node) {
  std::vector<Message> out;
  while (node.HasReady()) {
    Ready rd = node.GetReady();
    for (auto& m : rd.messages) out.push_back(m);
    node.Advance(rd);
  }
  return out;
}

inline std::vector<Message> Filter(const std::vector<Message>& msgs, MessageType type) {
  std::vector<Message> out;
  for (const auto& m : msgs) {
    if (m.type == type) out.push_back(m);
  }
  return out;
}

inline Message Msg(MessageType type, NodeId from, NodeId to, std::uint64_t term) {
  Message m;
  m.type = type;
  m.from = from;
  m.to = to;
  m.term = term;
  return m;
}

inline Entry Ent(std::uint64_t index, std::uint64_t term, std::string_view data = "") {
  return Entry{term, index, EntryType::kNormal, Bytes(data.begin(), data.end())};
}

// A cluster of RawNodes exchanging messages synchronously (no delay) until quiet.
class Network {
 public:
  // voters > 0: nodes 1..voters vote, the others are learners served every learner_ticks ticks.
  explicit Network(int n, bool pre_vote = false, bool check_quorum = false, int voters = 0,
                   int learner_ticks = 20) {
    for (int i = 1; i <= n; ++i) {
      Config c = MakeConfig(static_cast<NodeId>(i), n, pre_vote, check_quorum,
                            static_cast<std::uint64_t>(i), voters);
      c.learner_heartbeat_ticks = learner_ticks;
      nodes_.emplace(static_cast<NodeId>(i), std::make_unique<RawNode>(MakeNode(c)));
    }
  }
  RawNode& operator[](NodeId id) { return *nodes_.at(id); }

  // Drops messages matching the predicate.
  void SetDrop(std::function<bool(const Message&)> drop) { drop_ = std::move(drop); }
  void Isolate(NodeId id) {
    isolated_.insert(id);
  }
  void Recover() {
    isolated_.clear();
    drop_ = nullptr;
  }

  // Delivers the initial messages and everything they cause, in FIFO order.
  void Send(std::vector<Message> msgs) {
    std::deque<Message> q(msgs.begin(), msgs.end());
    for (auto& [id, n] : nodes_) {
      for (auto& m : Drain(*n)) q.push_back(m);
    }
    int guard = 0;
    while (!q.empty()) {
      ASSERT_LT(++guard, 100000) << "messages never stop";
      Message m = q.front();
      q.pop_front();
      if (isolated_.count(m.to) || isolated_.count(m.from)) continue;
      if (drop_ && drop_(m)) continue;
      RawNode& to = *nodes_.at(m.to);
      (void)to.Step(m);
      for (auto& out : Drain(to)) q.push_back(out);
    }
  }
  void Campaign(NodeId id) {
    Message m = Msg(MessageType::kHup, id, id, 0);
    Send({m});
  }
  void Propose(NodeId id, std::string_view data) {
    Message m = Msg(MessageType::kProp, id, id, 0);
    m.entries.push_back(Ent(0, 0, data));
    Send({m});
  }
  void TickAll(int ticks) {
    for (int t = 0; t < ticks; ++t) {
      for (auto& [id, n] : nodes_) n->Tick();  // isolation cuts messages, not clocks
      Send({});
    }
  }
  void Tick(NodeId id, int ticks) {
    for (int t = 0; t < ticks; ++t) {
      nodes_.at(id)->Tick();
      Send({});
    }
  }

 private:
  std::map<NodeId, std::unique_ptr<RawNode>> nodes_;
  std::set<NodeId> isolated_;
  std::function<bool(const Message&)> drop_;
};

}  // namespace swarmbox::raft::testing
