// MissionState: the swarm's replicated mission, a pure value type that every drone builds by
// applying the same committed Raft log in the same order (Raft §5.3 State Machine Safety).
//
//   MissionState m;
//   ApplyResult r = m.Apply(/*index=*/12, StartSearch{});     // r.accepted, r.events
//   Bytes snap = m.EncodeSnapshot();                           // Raft §7 log compaction
//   Result<MissionState> back = MissionState::DecodeSnapshot(snap);   // back == m
//
// Phases: IDLE -> SEARCH -> CONVERGE (on a confirmed victim) -> RESCUE (a heavy lifter picks the
// victim up) -> SEARCH again after MarkRescued ...; RETURN from SEARCH/CONVERGE/RESCUE; COMPLETE
// after RETURN. A command that does not fit the current state is *rejected*: the state does not
// change, the same way on every drone, and the result says why.
//
// Victim confirmation rule (deterministic, applied to ReportSighting in log order):
//   - a sighting with confidence >= kHighConfidence (0.9) confirms a victim on its own;
//   - otherwise two sightings with confidence >= kMinConfidence (0.5) from two *different* drones
//     within kConfirmRadiusM (5 m) of each other confirm a victim at their mean position;
//   - a sighting within kConfirmRadiusM of a known victim is that victim (no duplicate);
//   - sightings below kMinConfidence are rejected; unconfirmed sightings are kept (at most
//     kMaxPendingSightings, oldest dropped first) for a later match;
//   - each reporter's seq must increase: a retried proposal that commits twice is applied once.
// ConfirmVictim (an operator's word) confirms directly. Victim ids count up from 1.
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/raft/mission_command.hpp"

namespace swarmbox::raft {

enum class MissionPhase : std::uint8_t { kIdle, kSearch, kConverge, kRescue, kReturn, kComplete };
std::string_view PhaseName(MissionPhase phase);  // "IDLE", "SEARCH", ...

enum class VictimStatus : std::uint8_t { kConfirmed, kBeingRescued, kRescued };
std::string_view VictimStatusName(VictimStatus status);  // "confirmed", "being_rescued", "rescued"

struct Sighting {
  std::string reporter;
  std::uint64_t seq = 0;
  double x_m = 0, y_m = 0, confidence = 0;
  bool operator==(const Sighting&) const = default;
};

struct Victim {
  std::uint32_t id = 0;
  double x_m = 0, y_m = 0;  // ENU world frame [m]
  VictimStatus status = VictimStatus::kConfirmed;
  std::string rescuer;                    // the heavy lifter, once a rescue began
  std::vector<std::string> confirmed_by;  // reporters (or the operator) that confirmed it
  bool operator==(const Victim&) const = default;
};

// What applying one command changed, for the contract log events (node_driver.hpp prints them).
struct MissionEvent {
  enum class Kind : std::uint8_t {
    kPhase,            // event=mission_state state=<phase> index=<log index>
    kVictimConfirmed,  // event=victim_confirmed id= x= y=
    kVictimStatus,     // event=victim_status id= status= [rescuer=]
  };
  Kind kind = Kind::kPhase;
  MissionPhase phase = MissionPhase::kIdle;
  std::uint64_t index = 0;
  Victim victim;  // kVictimConfirmed / kVictimStatus: the victim after the change
  bool operator==(const MissionEvent&) const = default;
};

struct ApplyResult {
  bool accepted = false;
  std::string reason;  // why a command was rejected (empty when accepted)
  std::vector<MissionEvent> events;
};

class MissionState {
 public:
  static constexpr double kHighConfidence = 0.9;
  static constexpr double kMinConfidence = 0.5;
  static constexpr double kConfirmRadiusM = 5.0;
  static constexpr std::size_t kMaxPendingSightings = 64;
  static constexpr std::uint8_t kSnapshotVersion = 1;

  // Applies the command committed at log `index` (> applied_index(); aborts otherwise).
  ApplyResult Apply(std::uint64_t index, const MissionCommand& command);
  // Applies a log entry's bytes; undecodable bytes are rejected deterministically.
  ApplyResult ApplyEncoded(std::uint64_t index, std::span<const std::uint8_t> data);
  // An index without a command (the leader's no-op): only advances applied_index().
  void Skip(std::uint64_t index);

  Bytes EncodeSnapshot() const;
  static Result<MissionState> DecodeSnapshot(std::span<const std::uint8_t> bytes);

  std::uint64_t applied_index() const { return applied_index_; }
  MissionPhase phase() const { return phase_; }
  std::uint32_t target_victim() const { return target_victim_; }  // 0 = none
  const std::vector<Sector>& sectors() const { return sectors_; }
  const std::vector<Sighting>& pending_sightings() const { return pending_; }
  const std::vector<Victim>& victims() const { return victims_; }
  const Victim* FindVictim(std::uint32_t id) const;
  // The sector assigned to `drone`, or nullptr.
  const Sector* SectorOf(std::string_view drone) const;

  bool operator==(const MissionState&) const = default;

 private:
  ApplyResult Reject(std::string reason) const;
  ApplyResult ApplySighting(const ReportSighting& c);
  Victim* NearVictim(double x_m, double y_m);
  Victim& AddVictim(double x_m, double y_m, std::vector<std::string> by, ApplyResult* r);
  void SetPhase(MissionPhase phase, ApplyResult* r);

  std::uint64_t applied_index_ = 0;
  MissionPhase phase_ = MissionPhase::kIdle;
  std::uint32_t target_victim_ = 0;
  std::uint32_t next_victim_id_ = 1;
  std::vector<Sector> sectors_;
  std::map<std::string, std::uint64_t> last_seq_;  // per reporter
  std::vector<Sighting> pending_;
  std::vector<Victim> victims_;
};

}  // namespace swarmbox::raft
