// LeaderPlanner: what the Raft leader proposes to move the mission on, as a pure function of the
// committed mission state, the roster (drone names, roles and their published modes) and time.
// Runs only on the current leader; every proposal is idempotent or rejected harmlessly by
// MissionState, and re-proposed after retry_s while the state has not moved (lost proposals).
//
//   IDLE      all scouts airborne (or start_timeout_s)  -> AssignSectors(partition), StartSearch
//   SEARCH    a confirmed victim                         -> ConvergeOn(lowest id)
//   CONVERGE  a lifter on the ground or in "standby"      -> BeginRescue(target, lifter)
//             no lifter in the roster: after handle_time_s the victim counts as handled (scouts
//             orbited it) and the next confirmed victim is converged on
//   SEARCH/CONVERGE  every scout done ("swept"/returning/landed) and every victim rescued or
//             handled                                    -> ReturnHome
//   RETURN    every drone "landed"/"on_ground"           -> CompleteMission
//   COMPLETE  once: event=mission_complete victims=<n> rescued=<n>
//
//   planner.Step(t_s, driver.mission(), roster, &out);   // appends to out.proposals / out.events
#pragma once

#include <map>
#include <set>
#include <span>
#include <string>

#include "swarmbox/swarm/mission_types.hpp"
#include "swarmbox/swarm/search_pattern.hpp"

namespace swarmbox::swarm {

struct RosterEntry {
  std::string name;
  Role role = Role::kScout;
  std::string mode;  // bus::DroneState::mode, as the behaviours publish it
};

struct LeaderConfig {
  std::string name;               // this drone (the node in log events)
  Rect search_area;               // the area to partition among the scouts [m, ENU]
  double retry_s = 3.0;           // re-propose after this while the state has not moved
  double start_timeout_s = 60.0;  // start the search even if some scout is not airborne
  double handle_time_s = 45.0;    // no lifter: converge this long, then the victim is handled
};

class LeaderPlanner {
 public:
  explicit LeaderPlanner(LeaderConfig config);

  // Appends proposals and events to `out` (does not clear it or touch the setpoint).
  void Step(double t_s, const raft::MissionState& mission, std::span<const RosterEntry> roster,
            MissionOutput* out);

  bool handled(std::uint32_t victim_id) const { return handled_.count(victim_id) != 0; }

 private:
  bool Due(const std::string& key, double t_s);

  LeaderConfig config_;
  std::map<std::string, double> last_proposed_s_;
  std::map<std::uint32_t, double> converge_since_s_;
  std::set<std::uint32_t> handled_;
  bool complete_reported_ = false;
};

}  // namespace swarmbox::swarm
