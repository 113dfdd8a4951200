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
// Sightings, candidates and victims (deterministic, applied in log order; #19: a single view
// never confirms, however confident):
//   - a ReportSighting (confidence >= kMinConfidence, else rejected) within kConfirmRadiusM of a
//     confirmed victim is that victim (its reporter joins confirmed_by);
//   - otherwise it is a view of the nearest candidate within kConfirmRadiusM (pending or
//     rejected), or it opens a new candidate (ids count up from 1). A candidate's position is the
//     confidence-weighted mean of its closest detections (those from a camera height within
//     kCloseLookBand of the lowest); it keeps at most kMaxViews pieces of evidence;
//   - ReportMiss: a revisit saw nothing where the candidate is (evidence against it);
//   - RequestRevisit: the leader sends a drone to look again; the drone's next view or miss of
//     that candidate completes the revisit (revisits counts them); a request that replaces one
//     still under way (its drone gone or too slow) counts the abandoned one too, so a spot no
//     drone can reach is given up after the fusion's max_revisits (rubble20 on 2026-11-28: a
//     candidate revisited for ten minutes ran a trial out of time);
//   - ConfirmSighting / RejectSighting: the leader's decision from the fused evidence
//     (swarm/sighting_fusion.hpp weighs it; this state only records it, so that every drone and
//     every later leader sees the same decisions). Confirming adds a Victim; a rejected candidate
//     keeps collecting evidence and may still be confirmed later;
//   - each reporter's seq must increase (sightings and misses share it): a retried proposal that
//     commits twice is applied once;
//   - at most kMaxCandidates are kept: the oldest decided one goes first, else the oldest.
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

// One piece of evidence about a candidate: a detection (detected: its geolocated position and
// confidence) or a miss (not detected: a revisit had the candidate's place in view and saw
// nothing; x/y are the candidate's position then, confidence 0).
struct SightingView {
  std::string reporter;
  std::uint64_t seq = 0;
  double x_m = 0, y_m = 0, confidence = 0;
  double viewer_x_m = 0, viewer_y_m = 0, viewer_height_m = 0;  // the camera: ENU [m], above ground [m]
  double t_s = 0;                                               // capture, simulated [s]
  bool detected = true;
  bool operator==(const SightingView&) const = default;
};

enum class CandidateStatus : std::uint8_t { kPending, kConfirmed, kRejected };

// A place where some drone's detector fired, and everything seen there since.
struct Candidate {
  std::uint32_t id = 0;
  double x_m = 0, y_m = 0;  // ENU world frame [m]
  CandidateStatus status = CandidateStatus::kPending;
  std::vector<SightingView> views;  // in log order
  std::string revisit_drone;        // a revisit requested and not done yet ("": none)
  double revisit_t_s = 0;           // when it was requested (the leader's simulated time) [s]
  std::uint32_t revisits = 0;       // revisits done
  std::uint32_t victim_id = 0;      // kConfirmed: the victim it became
  double belief = 0;                // the fused belief of the decision (kConfirmed/kRejected)
  bool operator==(const Candidate&) const = default;
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
  static constexpr double kMinConfidence = 0.5;
  static constexpr double kConfirmRadiusM = 5.0;
  // A candidate's position averages the detections from at most 1.25 x the lowest camera height
  // among them: the scouts search from 30 m and the revisits look from 18 m (agent/app/sar_brain.hpp),
  // and a geolocation's error grows in proportion to the height (a pixel covers height / focal
  // length on the ground; an attitude error a moves the point by height * tan a), so a look from
  // 18 m places the person 0.6 as far off as one from 30 m.
  static constexpr double kCloseLookBand = 1.25;
  static constexpr std::size_t kMaxCandidates = 64;
  static constexpr std::size_t kMaxViews = 24;  // evidence per candidate; more is rejected
  static constexpr std::uint8_t kSnapshotVersion = 2;

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
  const std::vector<Candidate>& candidates() const { return candidates_; }
  const Candidate* FindCandidate(std::uint32_t id) const;
  // The candidate a sighting at (x_m, y_m) away from every victim is a view of: the nearest one
  // not confirmed within kConfirmRadiusM, or nullptr (the sighting opens a new one).
  const Candidate* CandidateAt(double x_m, double y_m) const;
  const std::vector<Victim>& victims() const { return victims_; }
  const Victim* FindVictim(std::uint32_t id) const;
  // The sector assigned to `drone`, or nullptr.
  const Sector* SectorOf(std::string_view drone) const;

  bool operator==(const MissionState&) const = default;

 private:
  // One handler per command (Apply dispatches): the phase, then the command, then the change.
  ApplyResult Handle(const StartSearch& c);
  ApplyResult Handle(const AssignSectors& c);
  ApplyResult Handle(const ReportSighting& c);
  ApplyResult Handle(const ConfirmVictim& c);
  ApplyResult Handle(const ConvergeOn& c);
  ApplyResult Handle(const BeginRescue& c);
  ApplyResult Handle(const MarkRescued& c);
  ApplyResult Handle(const ReturnHome& c);
  ApplyResult Handle(const CompleteMission& c);
  ApplyResult Handle(const ReportMiss& c);
  ApplyResult Handle(const RequestRevisit& c);
  ApplyResult Handle(const ConfirmSighting& c);
  ApplyResult Handle(const RejectSighting& c);
  // SEARCH, CONVERGE or RESCUE: the phases that take sightings, misses and decisions.
  bool Active() const;
  std::string InPhase() const;  // " in phase SEARCH", for rejections
  static ApplyResult Accepted();
  ApplyResult AcceptedEntering(MissionPhase phase);  // Accepted() with the phase change's event
  ApplyResult Reject(std::string reason) const;
  Victim& MutableVictim(std::uint32_t id);  // aborts when there is no such victim
  ApplyResult ApplySighting(const ReportSighting& c);
  ApplyResult ApplyMiss(const ReportMiss& c);
  // The reporter/seq rule shared by sightings and misses: empty when `seq` may be applied.
  std::string CheckSeq(const std::string& reporter, std::uint64_t seq) const;
  // A new pending candidate at (x_m, y_m); at kMaxCandidates the oldest decided one (or else the
  // oldest) makes room.
  Candidate& NewCandidate(double x_m, double y_m);
  Candidate* MutableCandidate(std::uint32_t id);
  void AddView(Candidate& c, SightingView v);
  Victim* NearVictim(double x_m, double y_m);
  Victim& AddVictim(double x_m, double y_m, std::vector<std::string> by, ApplyResult* r);
  void SetPhase(MissionPhase phase, ApplyResult* r);

  std::uint64_t applied_index_ = 0;
  MissionPhase phase_ = MissionPhase::kIdle;
  std::uint32_t target_victim_ = 0;
  std::uint32_t next_victim_id_ = 1;
  std::vector<Sector> sectors_;
  std::map<std::string, std::uint64_t> last_seq_;  // per reporter
  std::uint32_t next_candidate_id_ = 1;
  std::vector<Candidate> candidates_;
  std::vector<Victim> victims_;
};

}  // namespace swarmbox::raft
