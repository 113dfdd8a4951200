#include "brain_consensus.hpp"

namespace swarmbox::agent {

void RaftConsensus::TakeCommitted(std::vector<brain::Entry>* out) {
  raft_.TakeCommitted(&tap_);
  for (raft::Committed& c : tap_) out->push_back({c.index, std::move(c.data)});
}

bool RaftConsensus::Propose(std::span<const std::uint8_t> data) {
  return static_cast<bool>(raft_.ProposeBytes(raft::Bytes(data.begin(), data.end())));
}

void ReplicatedStateMachine::Apply(std::uint64_t index, std::span<const std::uint8_t> data,
                                   const raft::EventOut& /*events*/) {
  if (data.empty()) return;  // the leader's no-op (Raft §8): nothing of the brain's
  state_->Apply(index, data);
}

Status ReplicatedStateMachine::Restore(std::span<const std::uint8_t> snapshot) {
  if (state_->Restore(snapshot)) return Ok{};
  return Error(ErrorCode::kProtocol, "the Raft snapshot is not one of this brain's replicated state");
}

}  // namespace swarmbox::agent
