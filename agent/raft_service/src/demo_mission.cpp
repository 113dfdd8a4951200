#include "swarmbox/raft_service/demo_mission.hpp"

#include <string>

namespace swarmbox::raft_service {

std::optional<raft::MissionCommand> NextDemoCommand(const raft::MissionState& committed,
                                                    std::string_view self) {
  using raft::MissionPhase;
  switch (committed.phase()) {
    case MissionPhase::kIdle:
      return raft::StartSearch{};
    case MissionPhase::kSearch: {
      for (const raft::Victim& v : committed.victims()) {
        if (v.status == raft::VictimStatus::kConfirmed) return raft::ConvergeOn{v.id};
      }
      const double n = static_cast<double>(committed.victims().size() + 1);
      return raft::ConfirmVictim{std::string(self), kDemoVictimSpacingM * n, 0.0};
    }
    case MissionPhase::kConverge:
      return raft::BeginRescue{committed.target_victim(), std::string(self)};
    case MissionPhase::kRescue:
      return raft::MarkRescued{committed.target_victim()};
    case MissionPhase::kReturn:
      return raft::CompleteMission{};
    case MissionPhase::kComplete:
      return std::nullopt;
  }
  return std::nullopt;
}

}  // namespace swarmbox::raft_service
