// Mission commands: what the swarm proposes through Raft to change the replicated mission state
// (mission_state.hpp), and their binary encoding (the data of a Raft log entry).
//
// Coordinates are in the ENU world frame [m]; drones are named as in the trial (`scout_1`).
//
//   Bytes data = EncodeCommand(ReportSighting{"scout_2", 7, 41.5, -12.0, 0.72, 40, -10, 30, 61.2});
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
  // Where it was seen from: the camera's position (x, y ENU [m]) and height above the ground
  // [m], and the simulated capture time [s] (the evidence the fusion weighs, sighting_fusion.hpp).
  double viewer_x_m = 0, viewer_y_m = 0, viewer_height_m = 0;
  double t_s = 0;
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
// A revisit that looked at candidate `candidate` (its place in view, from the position given) and
// saw nothing there: evidence against it. Same seq rule as ReportSighting (one counter per drone).
struct ReportMiss {
  std::string reporter;
  std::uint64_t seq = 0;
  std::uint32_t candidate = 0;
  double viewer_x_m = 0, viewer_y_m = 0, viewer_height_m = 0;  // ENU [m], above ground [m]
  double t_s = 0;                                               // simulated [s]
  bool operator==(const ReportMiss&) const = default;
};
// The leader sends `drone` to look at an unconfirmed candidate again (replaces an earlier request).
struct RequestRevisit {
  std::uint32_t candidate = 0;
  std::string drone;
  double t_s = 0;  // the leader's simulated time of the request [s]
  bool operator==(const RequestRevisit&) const = default;
};
// The leader's decision from the fused evidence (sighting_fusion.hpp): the candidate is a victim.
struct ConfirmSighting {
  std::uint32_t candidate = 0;
  double belief = 0;  // the fused probability that decided it [0, 1]
  bool operator==(const ConfirmSighting&) const = default;
};
// The leader's decision: the candidate is a false alarm (kept, so later evidence is still fused).
struct RejectSighting {
  std::uint32_t candidate = 0;
  double belief = 0;
  bool operator==(const RejectSighting&) const = default;
};

using MissionCommand = std::variant<StartSearch, AssignSectors, ReportSighting, ConfirmVictim,
                                    ConvergeOn, BeginRescue, MarkRescued, ReturnHome,
                                    CompleteMission, ReportMiss, RequestRevisit, ConfirmSighting,
                                    RejectSighting>;

// 2: ReportSighting carries its viewpoint; candidates, misses, revisits and decisions (#19).
inline constexpr std::uint8_t kCommandVersion = 2;

std::string_view CommandName(const MissionCommand& command);  // "report_sighting", ...
Bytes EncodeCommand(const MissionCommand& command);
Result<MissionCommand> DecodeCommand(std::span<const std::uint8_t> bytes);

}  // namespace swarmbox::raft
