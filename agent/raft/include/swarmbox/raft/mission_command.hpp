// Mission commands: what the swarm proposes through Raft to change the replicated mission state
// (mission_state.hpp), and their binary encoding (the data of a Raft log entry).
//
// Coordinates are in the ENU world frame [m]; drones are named as in the trial (`scout_1`).
//
//   Bytes data = EncodeCommand(ReportSighting{"scout_2", 7, 41.5, -12.0, 0.72});
//   driver.Propose(ReportSighting{...});   // node_driver.hpp encodes for you
//
// Encoding: u8 version=1 | u8 kind | fields (strings and counts as varint-prefixed, doubles as
// 8-byte IEEE little endian). DecodeCommand returns kProtocol errors for anything malformed.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/raft/types.hpp"

namespace swarmbox::raft {

// An axis-aligned search rectangle in the ENU world frame [m], assigned to one drone.
struct Sector {
  std::string drone;
  double x_min_m = 0, y_min_m = 0, x_max_m = 0, y_max_m = 0;
  bool operator==(const Sector&) const = default;
};

struct StartSearch {  // IDLE -> SEARCH
  bool operator==(const StartSearch&) const = default;
};
struct AssignSectors {  // replaces every sector assignment (any phase but COMPLETE)
  std::vector<Sector> sectors;
  bool operator==(const AssignSectors&) const = default;
};
struct ReportSighting {  // a drone's detection of a possible victim
  std::string reporter;
  std::uint64_t seq = 0;  // per-reporter sequence number, > 0: retried proposals are applied once
  double x_m = 0, y_m = 0;
  double confidence = 0;  // [0, 1]
  bool operator==(const ReportSighting&) const = default;
};
struct ConfirmVictim {  // an operator (ground station) confirms a victim directly
  std::string by;
  double x_m = 0, y_m = 0;
  bool operator==(const ConfirmVictim&) const = default;
};
struct ConvergeOn {  // SEARCH/CONVERGE -> CONVERGE on a confirmed victim
  std::uint32_t victim_id = 0;
  bool operator==(const ConvergeOn&) const = default;
};
struct BeginRescue {  // CONVERGE (on that victim) -> RESCUE by a heavy lifter
  std::uint32_t victim_id = 0;
  std::string lifter;
  bool operator==(const BeginRescue&) const = default;
};
struct MarkRescued {  // RESCUE -> SEARCH, the victim is rescued
  std::uint32_t victim_id = 0;
  bool operator==(const MarkRescued&) const = default;
};
struct ReturnHome {  // SEARCH/CONVERGE/RESCUE -> RETURN
  bool operator==(const ReturnHome&) const = default;
};
struct CompleteMission {  // RETURN -> COMPLETE
  bool operator==(const CompleteMission&) const = default;
};

using MissionCommand = std::variant<StartSearch, AssignSectors, ReportSighting, ConfirmVictim,
                                    ConvergeOn, BeginRescue, MarkRescued, ReturnHome,
                                    CompleteMission>;

inline constexpr std::uint8_t kCommandVersion = 1;

std::string_view CommandName(const MissionCommand& command);  // "report_sighting", ...
Bytes EncodeCommand(const MissionCommand& command);
Result<MissionCommand> DecodeCommand(std::span<const std::uint8_t> bytes);

}  // namespace swarmbox::raft
