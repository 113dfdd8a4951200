#include "swarmbox/raft/conf_change.hpp"

#include <algorithm>

#include "swarmbox/raft/detail/byte_io.hpp"

namespace swarmbox::raft {

std::string_view ConfChangeOpName(ConfChangeOp op) {
  switch (op) {
    case ConfChangeOp::kAddLearner: return "add_learner";
    case ConfChangeOp::kPromoteLearner: return "promote";
    case ConfChangeOp::kRemoveNode: return "remove";
  }
  return "unknown";
}

Bytes EncodeConfChange(const ConfChange& change) {
  Bytes out;
  detail::ByteWriter w(&out);
  w.U8(static_cast<std::uint8_t>(change.op));
  w.Varint(change.node);
  return out;
}

Result<ConfChange> DecodeConfChange(std::span<const std::uint8_t> bytes) {
  detail::ByteReader r(bytes);
  const std::uint8_t op = r.U8();
  ConfChange c;
  c.node = r.Varint();
  if (r.ok() && !r.at_end()) r.Fail("trailing bytes");
  if (!r.ok()) return Error(ErrorCode::kProtocol, r.error(), "raft conf change");
  if (op < 1 || op > 3) {
    return Error(ErrorCode::kProtocol, "unknown conf change op " + std::to_string(op), "raft conf change");
  }
  if (c.node == kNoNode) return Error(ErrorCode::kProtocol, "conf change of node 0", "raft conf change");
  c.op = static_cast<ConfChangeOp>(op);
  return c;
}

bool IsVoter(const ConfState& conf, NodeId id) {
  return std::binary_search(conf.voters.begin(), conf.voters.end(), id);
}

bool IsLearner(const ConfState& conf, NodeId id) {
  return std::binary_search(conf.learners.begin(), conf.learners.end(), id);
}

namespace {

void Insert(std::vector<NodeId>* v, NodeId id) { v->insert(std::lower_bound(v->begin(), v->end(), id), id); }
void Erase(std::vector<NodeId>* v, NodeId id) { v->erase(std::lower_bound(v->begin(), v->end(), id)); }

}  // namespace

Result<ConfState> ApplyConfChange(const ConfState& conf, const ConfChange& change) {
  auto bad = [&](std::string why) {
    return Error(ErrorCode::kInvalidArgument,
                 std::string(ConfChangeOpName(change.op)) + " node " + std::to_string(change.node) + ": " + why,
                 "raft conf change");
  };
  if (change.node == kNoNode) return bad("node 0 is reserved");
  const bool voter = IsVoter(conf, change.node);
  const bool learner = IsLearner(conf, change.node);
  ConfState out = conf;
  switch (change.op) {
    case ConfChangeOp::kAddLearner:
      if (voter || learner) return bad(voter ? "already a voter" : "already a learner");
      Insert(&out.learners, change.node);
      return out;
    case ConfChangeOp::kPromoteLearner:
      if (!learner) return bad(voter ? "already a voter" : "not a learner");
      Erase(&out.learners, change.node);
      Insert(&out.voters, change.node);
      return out;
    case ConfChangeOp::kRemoveNode:
      if (!voter && !learner) return bad("not a member");
      if (voter && conf.voters.size() == 1) return bad("the last voter");
      Erase(voter ? &out.voters : &out.learners, change.node);
      return out;
  }
  return bad("unknown op");
}

}  // namespace swarmbox::raft
