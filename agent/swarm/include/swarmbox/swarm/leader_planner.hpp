// LeaderPlanner: what the Raft leader proposes to move the mission on, as a pure function of the
// committed mission state, the roster (drone names, roles, their published modes and how old the
// latest word from each is) and time. Runs only on the current leader; every proposal is
// idempotent or rejected harmlessly by MissionState, and re-proposed after retry_s while the
// state has not moved (lost proposals).
//
//   IDLE      all live scouts airborne (or start_timeout_s) -> AssignSectors(partition), StartSearch
//   SEARCH    a confirmed victim                         -> ConvergeOn(lowest id)
//   CONVERGE  a live lifter on the ground or "standby"   -> BeginRescue(target, lifter)
//             no lifter in the roster: after handle_time_s the victim counts as handled (scouts
//             orbited it) and the next confirmed victim is converged on
//   any active phase  a sector owned by a drone that is gone (below)
//                                                        -> AssignSectors: the orphaned sectors
//             split (along their longer side) among live scouts, nearest idle ones first
//   SEARCH/CONVERGE  every sector owned by a live scout that is done ("swept"/returning/landed),
//             every live scout done or without a sector, the sector list unchanged for
//             assignment_settle_s, and every victim rescued or handled -> ReturnHome
//   RETURN    every live drone "landed"/"on_ground"      -> CompleteMission
//   COMPLETE  once: event=mission_complete victims=<n> rescued=<n>
//
// A member is *gone* when its latest DroneState was taken more than member_timeout_s of
// simulated time ago (RosterEntry::age_s), or, never heard, member_timeout_s after this planner
// first ran. Simulated time is the right clock for it: the agents run in lockstep with the physics
// server, so a stalled (busy, swapped out) agent stops the clock for everyone and never looks
// silent, while a killed one stops publishing and ages at the rate of the world. Only the radio
// adds age to a live member, in wall time: at rtf 1 a state sample (5 Hz, reliable, keep-last 1)
// over 100 +- 20 ms delay with 5% loss is rarely more than 0.3 s old, and 6 s of silence means 30
// lost samples in a row (0.05^30); at rtf 0 the age is that wall delay times the speed-up, still
// far below 6 s while the world runs under ~10x real time. A member wrongly taken for gone only
// costs a repeated sweep (its sector goes to others; when it is heard again it is a live scout
// without a sector, done and free for the next hand-over), never a wrong ending.
//
// The planner keeps no state a new leader could not rebuild: sectors and their owners live in the
// committed MissionState; what it tracks (when the sector list last changed, who it reported
// lost) is re-learned from the committed state and the roster. Track() runs on every drone each
// mission tick so that a follower that becomes leader already knows when the list last changed.
//
//   planner.Track(t_s, driver.mission());                       // every drone, every tick
//   planner.Step(t_s, driver.mission(), roster, &out);          // the leader: appends proposals
#pragma once

#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "swarmbox/swarm/mission_types.hpp"
#include "swarmbox/swarm/search_pattern.hpp"

namespace swarmbox::swarm {

struct RosterEntry {
  std::string name;
  Role role = Role::kScout;
  std::string mode;  // bus::DroneState::mode, as the behaviours publish it
  double age_s = 0;  // simulated time since the latest DroneState was taken (0: this drone) [s]
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
  // The sector list must be unchanged this long before the search counts as finished: an owner
  // that was just handed a sector may still publish the "swept" of before it applied the commit.
  // A follower applies a commit within a heartbeat or two of the leader (200 ms + 100 ms radio
  // here, a few retries under 5% loss) and is heard 0.2 s later: 10 s of simulated time covers
  // that up to a ~10x speed-up [s].
  double assignment_settle_s = 10.0;
};

class LeaderPlanner {
 public:
  explicit LeaderPlanner(LeaderConfig config);

  // Follows the committed sector list (when it last changed). Step() calls it too.
  void Track(double t_s, const raft::MissionState& mission);

  // Appends proposals and events to `out` (does not clear it or touch the setpoint).
  void Step(double t_s, const raft::MissionState& mission, std::span<const RosterEntry> roster,
            MissionOutput* out);

  bool handled(std::uint32_t victim_id) const { return handled_.count(victim_id) != 0; }
  // Whether `entry` is alive at `t_s` by the rule in the banner.
  bool Alive(const RosterEntry& entry) const { return entry.age_s <= config_.member_timeout_s; }

 private:
  bool Due(const std::string& key, double t_s);
  // The sectors of drones that are gone handed to live scouts; nullopt when there is nothing to
  // hand over or nobody to take it.
  std::optional<raft::AssignSectors> Reassign(double t_s, const raft::MissionState& m,
                                              std::span<const RosterEntry> roster,
                                              MissionOutput* out) const;
  bool GoneOwner(double t_s, const std::string& drone, std::span<const RosterEntry> roster) const;
  void ReportMembers(double t_s, std::span<const RosterEntry> roster, MissionOutput* out);

  LeaderConfig config_;
  std::map<std::string, double> last_proposed_s_;
  std::map<std::uint32_t, double> converge_since_s_;
  std::set<std::uint32_t> handled_;
  bool complete_reported_ = false;
  bool tracking_ = false;                 // Track() ran before
  double first_s_ = 0.0;                  // first Track() [s]
  std::vector<raft::Sector> sectors_;     // the committed list as last seen
  double sectors_changed_s_ = 0.0;        // when it last changed (or was first seen) [s]
  std::set<std::string> lost_;            // members reported lost (event=member_lost)
};

}  // namespace swarmbox::swarm
