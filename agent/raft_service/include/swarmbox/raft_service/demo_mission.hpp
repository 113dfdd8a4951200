// DemoMission: the mission command a stand-alone Raft node (swarmbox-raft-node) proposes next,
// given the committed mission. It walks the mission state machine (mission_state.hpp) in an
// endless loop so that every committed step is visible as a contract event:
//   IDLE     -> StartSearch                          (event=mission_state state=SEARCH)
//   SEARCH   -> ConfirmVictim at (30 * n, 0) m       (event=victim_confirmed id=n), when no
//               confirmed victim waits; else ConvergeOn(that victim)  (state=CONVERGE)
//   CONVERGE -> BeginRescue(target, lifter = self)   (state=RESCUE)
//   RESCUE   -> MarkRescued(target)                  (state=SEARCH)
//   RETURN   -> CompleteMission; COMPLETE -> nothing.
// A command proposed again before the previous one committed is rejected deterministically on
// every drone (mission_state.hpp), so proposing on a timer is safe.
// Pure: no I/O, no state. Thread-safety: none needed.
#pragma once

#include <optional>
#include <string_view>

#include "swarmbox/raft/mission_command.hpp"
#include "swarmbox/raft/mission_state.hpp"

namespace swarmbox::raft_service {

inline constexpr double kDemoVictimSpacingM = 30.0;  // > MissionState::kConfirmRadiusM

std::optional<raft::MissionCommand> NextDemoCommand(const raft::MissionState& committed,
                                                    std::string_view self);

}  // namespace swarmbox::raft_service
