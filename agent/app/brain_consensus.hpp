// A brain's view of the swarm's Raft log, both directions of the adapter:
//   RaftConsensus : ConsensusPort        BrainHost -> RaftHost (leader, the committed-entries tap,
//                                        proposals as bytes)
//   ReplicatedStateMachine : raft::StateMachine
//                                        a brain's own brain::ReplicatedState replicated by Raft
//                                        (Apply per committed entry, Snapshot/Restore)
//
//   auto state = brain->MakeReplicatedState();                  // null: the entry log
//   auto machine = state ? std::make_unique<ReplicatedStateMachine>(state.get())
//                        : std::unique_ptr<raft::StateMachine>(std::make_unique<raft::EntryLogMachine>());
//   auto raft = RaftHost::Start(options, radio, clock, log, &sim_clock, std::move(machine));
//   RaftConsensus consensus(**raft);
//
// The SDK does not depend on Raft (ARCHITECTURE.md "Brains"): these adapters are the agent's. Ownership: the
// ReplicatedState and the RaftHost outlive their adapters. Not thread-safe (the control loop).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "brain_host.hpp"
#include "raft_host.hpp"
#include "swarmbox/brain/brain.hpp"
#include "swarmbox/raft/state_machine.hpp"

namespace swarmbox::agent {

class RaftConsensus final : public ConsensusPort {
 public:
  explicit RaftConsensus(RaftHost& raft) : raft_(raft) {}
  bool is_leader() const override { return raft_.is_leader(); }
  std::string leader() const override { return raft_.leader(); }
  void TakeCommitted(std::vector<brain::Entry>* out) override;
  // kUnavailable (no leader known) and the stop error: false.
  bool Propose(std::span<const std::uint8_t> data) override;

 private:
  RaftHost& raft_;
  std::vector<raft::Committed> tap_;  // reused
};

// Apply skips the leader's no-ops (empty entries); Restore's false is kProtocol ("not a snapshot of
// this brain's state"): the Raft node then stops (raft_stopped) and the agent exits 1.
class ReplicatedStateMachine final : public raft::StateMachine {
 public:
  explicit ReplicatedStateMachine(brain::ReplicatedState* state) : state_(state) {}
  void Apply(std::uint64_t index, std::span<const std::uint8_t> data, const raft::EventOut& events) override;
  raft::Bytes Snapshot() const override { return state_->Snapshot(); }
  Status Restore(std::span<const std::uint8_t> snapshot) override;

 private:
  brain::ReplicatedState* state_;
};

}  // namespace swarmbox::agent
