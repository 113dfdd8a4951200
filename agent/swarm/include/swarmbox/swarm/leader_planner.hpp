// LeaderPlanner: what the Raft leader proposes to move the mission on, as a pure function of the
// committed mission state, the roster (drone names, roles, their published modes and how old the
// latest word from each is) and time. Runs only on the current leader; every proposal is
// idempotent or rejected harmlessly by MissionState, and re-proposed after retry_s while the
// state has not moved (lost proposals).
//
//   IDLE      all live scouts airborne (or start_timeout_s) -> ONE AssignSectors for every scout
//             (PartitionArea's near-square grid, cells matched to where the scouts are by
//             PartitionOrder), StartSearch
//   SEARCH    a confirmed victim                         -> ConvergeOn(lowest id)
//   SEARCH/CONVERGE/RESCUE  candidates (unconfirmed sightings, raft::Candidate), weighed by
//             sighting_fusion.hpp: enough independent evidence -> ConfirmSighting (a victim, to
//             be rescued like any other; only confirmed victims are rescued); too little after
//             misses -> RejectSighting; no new view for revisit_after_s -> RequestRevisit (a
//             live scout, idle ones first, then the nearest, one revisit per scout at a time; a
//             revisit not done in revisit_timeout_s or whose drone is gone goes to another)
//   CONVERGE  a live lifter on the ground or "standby"   -> BeginRescue(target, lifter)
//             no lifter in the roster: after handle_time_s the victim counts as handled (scouts
//             orbited it) and the next confirmed victim is converged on
//   any active phase  a sector owned by a drone that is gone (below)
//                                                        -> AssignSectors: the orphaned sectors
//             split (along their longer side) among live scouts, nearest idle ones first
//   SEARCH/CONVERGE  every sector owned by a live scout that is done ("swept"/returning/landed),
//             every live scout done or without a sector, the sector list unchanged for
//             assignment_settle_s, no candidate pending, and every victim rescued or handled
//             -> ReturnHome
//   RETURN    every live drone "landed"/"on_ground"      -> CompleteMission
//   COMPLETE  once: event=mission_complete victims=<n> rescued=<n>
//
// A member is *gone* when its latest DroneState was taken more than member_timeout_s of
// simulated time ago (RosterEntry::age_s) AND was received at least member_min_wall_s of wall
// time ago (RosterEntry::wall_age_s), or, never heard, both that long after this planner first
// ran. Simulated time is the clock of the rule: the agents run in lockstep with the physics
// server, so a stalled (busy, swapped out) agent stops the clock for everyone, while a killed one
// stops publishing and ages at the rate of the world. But the radio (DDS on the mesh, 100 +- 20
// ms of netem delay in containers) delivers in wall time, and at rtf 0 the world runs many times
// faster than the wall clock: a state sample held back ~1 s of wall time (a starved receive or
// publish thread, DDS repairing a loss) is then 6+ simulated seconds old on arrival. At load ~42
// on two cores a leader at rtf 0 declared every member lost at once (member_lost silent_s=6.1)
// and the mission took 390 s instead of ~225 s. Hence the wall-clock floor: 3 s is ten times the
// worst radio delay of a live member at rtf 1 (a 5 Hz sample over 100 +- 20 ms with 5% loss is
// rarely 0.3 s old) and leaves ~2 s for starvation and DDS repair. At rtf 1 (and whenever the
// world runs no faster than 2x real time) 6 s of simulated silence is already >= 3 s of wall
// time, so the simulated rule decides alone, as before; at rtf 0 a killed member is noticed after
// max(6 s simulated, 3 s wall), i.e. ~25 s simulated at the ~8x of the loopback test. 6 s of
// simulated silence at rtf 1 means 30 lost samples in a row (0.05^30). Without a wall clock
// (wall_age_s infinite, wall_s NaN: the default) the simulated rule decides alone. A member
// wrongly taken for gone only costs a repeated sweep (its sector goes to others; when it is heard
// again it is a live scout without a sector, done and free for the next hand-over), never a wrong
// ending.
//
// The planner keeps no state a new leader could not rebuild: sectors and their owners live in the
// committed MissionState; what it tracks (when the sector list last changed, who it reported
// lost) is re-learned from the committed state and the roster. Track() runs on every drone each
// mission tick so that a follower that becomes leader already knows when the list last changed.
//
// Evidence events (the leader logs them, from the committed state, with the fused belief):
//   event=sighting   a new view or miss of a candidate (candidate, reporter, seen, confidence,
//                    viewer x:y:h, capture t, and the belief after it)
//   event=revisit    a revisit committed (candidate, drone, belief)
//   event=confirmed  a candidate confirmed (victim id and every view: drones, confidences, viewers, t)
//   event=rejected   a candidate rejected (reason=belief|undecided and every view)
// Track() notices them on every drone (so a new leader does not repeat what it saw before it
// led) and Step() hands over those of the current tick; a drone's first Track() only learns.
//
//   planner.Track(t_s, driver.mission(), wall_s);               // every drone, every tick
//   planner.Step(t_s, driver.mission(), roster, &out, wall_s);  // the leader: appends proposals
//
// The roster is every member heard, in any order (MemberTable::Roster keeps it per message).
// Cost of a Step: O(N log N) for N members (one sort of pointers by name, then O(log N) lookups
// per sector owner), no allocation once the scratch vectors have grown; 100 scouts at the 10 Hz
// mission tick are ~1,000 comparisons per tick on the leader only.
//
// wall_s is any monotonic wall clock [s] (steady_clock), read by the caller: the planner reads
// no clock.
#pragma once

#include <limits>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "swarmbox/swarm/mission_types.hpp"
#include "swarmbox/swarm/search_pattern.hpp"
#include "swarmbox/swarm/sighting_fusion.hpp"

namespace swarmbox::swarm {

struct RosterEntry {
  std::string name;
  Role role = Role::kScout;
  std::string mode;  // bus::DroneState::mode, as the behaviours publish it
  double age_s = 0;  // simulated time since the latest DroneState was taken (0: this drone) [s]
  // Wall time since the latest DroneState was received (0: this drone; infinite: no wall clock,
  // the simulated age alone decides) [s].
  double wall_age_s = std::numeric_limits<double>::infinity();
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();  // its latest position, world ENU [m]
};

struct LeaderConfig {
  std::string name;               // this drone (the node in log events)
  Rect search_area;               // the area to partition among the scouts [m, ENU]
  double retry_s = 3.0;           // re-propose after this while the state has not moved
  double start_timeout_s = 60.0;  // start the search even if some scout is not airborne
  double handle_time_s = 45.0;    // no lifter: converge this long, then the victim is handled
  // A member silent this long (simulated time) is gone: see the banner for why 6 s [s].
  double member_timeout_s = 6.0;
  // ... and silent at least this long on the wall clock (rtf 0: the radio's wall-time delays are
  // many simulated seconds): see the banner for why 3 s [s].
  double member_min_wall_s = 3.0;
  // The sector list must be unchanged this long before the search counts as finished: an owner
  // that was just handed a sector may still publish the "swept" of before it applied the commit.
  // A follower applies a commit within a heartbeat or two of the leader (200 ms + 100 ms radio
  // here, a few retries under 5% loss) and is heard 0.2 s later: 10 s of simulated time covers
  // that up to a ~10x speed-up [s].
  double assignment_settle_s = 10.0;
  FusionParams fusion{};  // confirming, rejecting and revisiting candidates (sighting_fusion.hpp)
};

class LeaderPlanner {
 public:
  explicit LeaderPlanner(LeaderConfig config);

  // Follows the committed sector list (when it last changed). Step() calls it too.
  // wall_s: a monotonic wall clock [s]; NaN: none (the simulated clock alone decides).
  void Track(double t_s, const raft::MissionState& mission,
             double wall_s = std::numeric_limits<double>::quiet_NaN());

  // Appends proposals and events to `out` (does not clear it or touch the setpoint).
  void Step(double t_s, const raft::MissionState& mission, std::span<const RosterEntry> roster,
            MissionOutput* out, double wall_s = std::numeric_limits<double>::quiet_NaN());

  bool handled(std::uint32_t victim_id) const { return handled_.count(victim_id) != 0; }
  // Whether `entry` is alive at `t_s` by the rule in the banner.
  bool Alive(const RosterEntry& entry) const {
    return entry.age_s <= config_.member_timeout_s || entry.wall_age_s < config_.member_min_wall_s;
  }

 private:
  struct Fleet;
  bool Due(const std::string& key, double t_s);
  // Step's parts, in order: the live scouts and lifter; the sectors of gone drones handed over
  // (returns whether any sector is orphaned); whether the search is finished; then one plan per
  // phase.
  Fleet Survey(std::span<const RosterEntry> roster) const;
  bool ProposeReassign(double t_s, const raft::MissionState& m, std::span<const RosterEntry> roster,
                       MissionOutput* out);
  bool ScoutsDone(double t_s, const raft::MissionState& m, std::span<const RosterEntry> roster,
                  bool orphans);
  const raft::Victim* FirstUnhandled(const raft::MissionState& m) const;  // confirmed, not handled
  void PlanStart(double t_s, const raft::MissionState& m, const Fleet& fleet, MissionOutput* out);
  // SEARCH / CONVERGE: rescue or orbit the target, converge on the next victim, or go home once
  // `search_finished` (scouts done, no rescue running, no candidate undecided).
  void PlanSearch(double t_s, const raft::MissionState& m, const Fleet& fleet, bool search_finished,
                  MissionOutput* out);
  void ReportComplete(double t_s, const raft::MissionState& m, MissionOutput* out);
  // The sectors of drones that are gone handed to live scouts; nullopt when there is nothing to
  // hand over or nobody to take it.
  std::optional<raft::AssignSectors> Reassign(double t_s, const raft::MissionState& m,
                                              std::span<const RosterEntry> roster,
                                              MissionOutput* out) const;
  bool GoneOwner(double t_s, const std::string& drone) const;  // by_name_ of this Step
  void Index(std::span<const RosterEntry> roster);             // fills by_name_
  const RosterEntry* Find(const std::string& drone) const;     // O(log N) in by_name_
  void ReportMembers(double t_s, std::span<const RosterEntry> roster, MissionOutput* out);
  // Evidence events of the committed candidates that changed since the last Track().
  void TrackCandidates(double t_s, const raft::MissionState& m, bool learn_only);
  // Decisions and revisits for the candidates (active phases); returns whether any is pending.
  bool PlanCandidates(double t_s, const raft::MissionState& m, std::span<const RosterEntry> roster,
                      MissionOutput* out);
  // PlanCandidates' parts: whether a pending candidate needs a (new) revisit; the scout to send
  // (live, not busy, most available, then nearest, then by name; null: none).
  bool RevisitNeeded(double t_s, const raft::Candidate& c, const FusionAssessment& a) const;
  const RosterEntry* PickRevisitor(const raft::Candidate& c, std::span<const RosterEntry> roster,
                                   const std::set<std::string>& busy) const;

  LeaderConfig config_;
  std::map<std::string, double> last_proposed_s_;
  std::map<std::uint32_t, double> converge_since_s_;
  std::set<std::uint32_t> handled_;
  bool complete_reported_ = false;
  bool tracking_ = false;                 // Track() ran before
  double first_s_ = 0.0;                  // first Track() [s]
  double first_wall_s_ = 0.0;             // its wall clock (NaN: none) [s]
  double wall_s_ = 0.0;                   // the wall clock of the latest Track() (NaN: none) [s]
  std::vector<raft::Sector> sectors_;     // the committed list as last seen
  double sectors_changed_s_ = 0.0;        // when it last changed (or was first seen) [s]
  std::set<std::string> lost_;            // members reported lost (event=member_lost)
  struct SeenCandidate {
    std::size_t views = 0;
    raft::CandidateStatus status = raft::CandidateStatus::kPending;
    std::string revisit_drone;
  };
  std::map<std::uint32_t, SeenCandidate> seen_;  // the candidates as last tracked
  double tracked_s_ = -1.0;                      // the latest Track()'s time [s]
  std::vector<LogEvent> evidence_events_;        // of the latest tracked tick, for Step()
  // Scratch of one Step (capacity kept): the roster by name, the sector owners by name.
  std::vector<const RosterEntry*> by_name_;
  std::vector<const std::string*> owners_;
};

}  // namespace swarmbox::swarm
