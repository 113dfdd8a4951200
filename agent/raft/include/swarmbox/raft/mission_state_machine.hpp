// MissionStateMachine: SwarmBox's SAR mission (MissionState, mission_state.hpp) as a Raft
// StateMachine (state_machine.hpp). Entries are encoded MissionCommands (mission_command.hpp);
// the snapshot is MissionState::EncodeSnapshot(). The default machine of NodeDriver::Open,
// RaftService::Start and the agent's RaftHost.
//
// Event lines (the logfmt contract, on every node, when the entry is applied):
//   event=mission_state state=SEARCH index=12                      a committed phase change
//   event=victim_confirmed id=1 x=41.500 y=-12.000 index=14        a committed confirmation
//   event=victim_status id=1 status=being_rescued rescuer=lifter index=20
//   event=mission_state state=SEARCH index=64 from=snapshot        a snapshot from the leader
//                                                                  replaced the state
// Rejected commands (wrong phase, undecodable bytes) change nothing and print nothing. A restored
// snapshot replays no entries to the committed-entries tap (ReplayRestored: none): the mission
// state stands for them.
#pragma once

#include <cstdint>
#include <span>

#include "swarmbox/raft/mission_state.hpp"
#include "swarmbox/raft/state_machine.hpp"

namespace swarmbox::raft {

class MissionStateMachine final : public StateMachine {
 public:
  MissionStateMachine() = default;
  explicit MissionStateMachine(MissionState mission) : mission_(std::move(mission)) {}

  void Apply(std::uint64_t index, std::span<const std::uint8_t> data,
             const EventOut& events) override;
  Bytes Snapshot() const override { return mission_.EncodeSnapshot(); }
  Status Restore(std::span<const std::uint8_t> snapshot) override;
  void OnSnapshotInstalled(std::uint64_t index, const EventOut& events) override;

  const MissionState& mission() const { return mission_; }

 private:
  MissionState mission_;
};

// The event lines of one applied command's MissionEvents, in order (what Apply emits).
void EmitMissionEvents(const ApplyResult& result, const EventOut& events);

}  // namespace swarmbox::raft
