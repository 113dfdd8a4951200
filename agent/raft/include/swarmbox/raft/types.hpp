// Raft value types: log entries, hard state, snapshots and messages.
//
// The vocabulary of the Raft library (agent/raft), shaped like etcd-io/raft's raftpb. Everything
// here is a plain value: no I/O, no clocks. Node ids are small integers (1..n, 0 = none); the node
// driver maps them to drone names (node_driver.hpp).
//
// Paper references: "Raft §x" is Ongaro & Ousterhout, "In Search of an Understandable Consensus
// Algorithm" (USENIX ATC 2014); "thesis §x" is Ongaro's PhD thesis "Consensus: Bridging Theory and
// Practice" (2014), which adds PreVote (§9.6) and CheckQuorum (§6.2).
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

namespace swarmbox::raft {

using Bytes = std::vector<std::uint8_t>;
using NodeId = std::uint64_t;
inline constexpr NodeId kNoNode = 0;

enum class EntryType : std::uint8_t {
  kNormal = 0,  // an application command (opaque bytes)
  kEmpty = 1,   // the no-op a new leader appends to commit entries of earlier terms (Raft §8)
  kConfChange = 2,  // a membership change (conf_change.hpp), applied when it is applied
};
inline constexpr std::uint8_t kMaxEntryType = 2;

struct Entry {
  std::uint64_t term = 0;
  std::uint64_t index = 0;
  EntryType type = EntryType::kNormal;
  Bytes data;

  bool operator==(const Entry&) const = default;
};

// The state that must be durable before any message depending on it is sent (Raft §5, Figure 2
// "Persistent state on all servers"; commit is kept too so that a restart re-applies less).
struct HardState {
  std::uint64_t term = 0;
  NodeId vote = kNoNode;
  std::uint64_t commit = 0;

  bool operator==(const HardState&) const = default;
};

// The cluster's membership (etcd-io/raft's ConfState): the voters, who elect the leader and form
// the quorums, and the learners, who receive and apply the log but never vote, never campaign and
// never count for a quorum. Both sorted, disjoint. Empty voters = "not recorded" (a snapshot
// written before membership changes existed: the node's configured membership applies).
struct ConfState {
  std::vector<NodeId> voters;
  std::vector<NodeId> learners;

  bool empty() const { return voters.empty(); }
  bool operator==(const ConfState&) const = default;
};

// A snapshot of the replicated state machine up to and including `index` (Raft §7), with the
// membership in effect at that index. `data` is the state machine's own encoding
// (MissionState::EncodeSnapshot). index 0 = none.
struct Snapshot {
  std::uint64_t index = 0;
  std::uint64_t term = 0;
  Bytes data;
  ConfState conf = {};

  bool empty() const { return index == 0; }
  bool operator==(const Snapshot&) const = default;
};

enum class MessageType : std::uint8_t {
  // Local messages: never sent on the wire (the codec refuses them).
  kHup = 0,          // start an election (from Tick on election timeout)
  kBeat = 1,         // leader: broadcast heartbeats (from Tick)
  kCheckQuorum = 2,  // leader: step down without a recently active quorum (thesis §6.2)
  // Wire messages.
  kProp = 3,           // proposal; a follower forwards it to its leader
  kApp = 4,            // AppendEntries RPC (Raft §5.3)
  kAppResp = 5,        // its response
  kVote = 6,           // RequestVote RPC (Raft §5.2)
  kVoteResp = 7,       //
  kPreVote = 8,        // PreVote RPC (thesis §9.6)
  kPreVoteResp = 9,    //
  kSnap = 10,          // InstallSnapshot RPC (Raft §7)
  kHeartbeat = 11,     // empty AppendEntries carrying only the commit index (Raft §5.2)
  kHeartbeatResp = 12, //
};
inline constexpr std::uint8_t kMaxMessageType = 12;

std::string_view MessageTypeName(MessageType type);
bool IsLocalMessage(MessageType type);

struct Message {
  MessageType type = MessageType::kHup;
  NodeId from = kNoNode;
  NodeId to = kNoNode;
  std::uint64_t term = 0;
  std::uint64_t log_term = 0;  // kApp: term of entry `index`; kVote/kPreVote: candidate's last term
  std::uint64_t index = 0;     // kApp: index preceding `entries`; kAppResp: match or rejected index
  std::uint64_t commit = 0;    // leader's commit index (kApp, kHeartbeat)
  bool reject = false;
  std::uint64_t reject_hint = 0;  // kAppResp reject: the follower's last index, for fast back-off
  std::vector<Entry> entries;
  Snapshot snapshot;  // kSnap only

  bool operator==(const Message&) const = default;
};

}  // namespace swarmbox::raft
