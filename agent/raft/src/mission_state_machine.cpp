#include "swarmbox/raft/mission_state_machine.hpp"

namespace swarmbox::raft {

void EmitMissionEvents(const ApplyResult& result, const EventOut& events) {
  for (const MissionEvent& ev : result.events) {
    switch (ev.kind) {
      case MissionEvent::Kind::kPhase:
        events.Emit(events.New("mission_state")
                        .Add("state", PhaseName(ev.phase))
                        .Add("index", ev.index));
        break;
      case MissionEvent::Kind::kVictimConfirmed:
        events.Emit(events.New("victim_confirmed")
                        .Add("id", static_cast<std::uint64_t>(ev.victim.id))
                        .Add("x", ev.victim.x_m)
                        .Add("y", ev.victim.y_m)
                        .Add("index", ev.index));
        break;
      case MissionEvent::Kind::kVictimStatus: {
        LogEvent le = events.New("victim_status");
        le.Add("id", static_cast<std::uint64_t>(ev.victim.id))
            .Add("status", VictimStatusName(ev.victim.status));
        if (!ev.victim.rescuer.empty()) le.Add("rescuer", ev.victim.rescuer);
        events.Emit(le.Add("index", ev.index));
        break;
      }
    }
  }
}

void MissionStateMachine::Apply(std::uint64_t index, std::span<const std::uint8_t> data,
                                const EventOut& events) {
  if (data.empty()) {  // the leader's no-op
    mission_.Skip(index);
    return;
  }
  EmitMissionEvents(mission_.ApplyEncoded(index, data), events);
}

Status MissionStateMachine::Restore(std::span<const std::uint8_t> snapshot) {
  auto m = MissionState::DecodeSnapshot(snapshot);
  if (!m) return m.error();
  mission_ = std::move(*m);
  return Ok{};
}

void MissionStateMachine::OnSnapshotInstalled(std::uint64_t index, const EventOut& events) {
  events.Emit(events.New("mission_state")
                  .Add("state", PhaseName(mission_.phase()))
                  .Add("index", index)
                  .Add("from", "snapshot"));
}

}  // namespace swarmbox::raft
