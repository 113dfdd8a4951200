// Membership changes: etcd-io/raft's one-at-a-time ConfChange (not joint consensus).
//
// A change is a log entry (EntryType::kConfChange, data = EncodeConfChange) proposed by the leader
// and committed like any other entry; every node switches to the new configuration when it
// *applies* the entry (RawNode::Advance), as etcd does. Three operations:
//   kAddLearner      a node that is no member becomes a learner (receives the log, never votes);
//   kPromoteLearner  a learner becomes a voter;
//   kRemoveNode      a voter or a learner leaves the configuration.
// Each changes the voter set by at most one node, so any majority of the old voters and any
// majority of the new ones overlap (Raft thesis §4.1, "single-server changes"). Safety also needs
// (thesis §4.1, the bug Ongaro posted to raft-dev in 2015, and etcd's pendingConfIndex):
//   - at most one change in flight: the leader refuses a second change while one it appended is
//     not yet applied;
//   - a new leader proposes a change only after it applied the no-op of its own term, i.e. after
//     it committed an entry of its term.
// Both are enforced by RawNode::ProposeConfChange; the cluster simulator checks them.
//
// ConfState in snapshots: a snapshot carries the configuration in effect at its index, so a node
// restored from a snapshot, or restarted from one, has the right membership without the log
// before it; the committed entries after the snapshot re-apply the later changes.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"
#include "swarmbox/raft/types.hpp"

namespace swarmbox::raft {

enum class ConfChangeOp : std::uint8_t { kAddLearner = 1, kPromoteLearner = 2, kRemoveNode = 3 };

// "add_learner", "promote", "remove" (the op= of event=raft_conf_change).
std::string_view ConfChangeOpName(ConfChangeOp op);

struct ConfChange {
  ConfChangeOp op = ConfChangeOp::kAddLearner;
  NodeId node = kNoNode;

  bool operator==(const ConfChange&) const = default;
};

// u8 op | varint node.
Bytes EncodeConfChange(const ConfChange& change);
// kProtocol for a malformed entry (unknown op, node 0, truncation, trailing bytes).
Result<ConfChange> DecodeConfChange(std::span<const std::uint8_t> bytes);

// The configuration after `change`, or kInvalidArgument saying why it does not apply: adding a
// node that is already a member, promoting a non-learner, removing a non-member or the last
// voter. Pure and deterministic: every node applying the same committed changes to the same
// starting configuration reaches the same one.
Result<ConfState> ApplyConfChange(const ConfState& conf, const ConfChange& change);

bool IsVoter(const ConfState& conf, NodeId id);
bool IsLearner(const ConfState& conf, NodeId id);

}  // namespace swarmbox::raft
