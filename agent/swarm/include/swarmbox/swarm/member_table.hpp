// MemberTable: what a drone knows of every member of the mission (role, mode, where it is and
// how old that word is), kept per heard message in O(1) so that the leader planner sees the whole
// swarm without a rebuild per step. At 100 drones an agent no longer gets every peer's state in
// every step (the agent hands a brain the 32 nearest, agent/brain's README): the table is fed by
// whatever carries a member's word (a nearby drone's DroneState, a far one's status message) and
// remembers it, and LeaderPlanner reads it as its roster.
//
//   MemberTable table(members, "scout_1");                  // the trial's drones, same on every drone
//   table.Update("scout_7", t_s, Role::kScout, "searching", xy);   // per message: O(1)
//   table.UpdateSelf(now_s, role, mode, xy);                 // this drone, every tick
//   planner.Step(now_s, mission, table.Roster(now_s), &out); // ages refreshed in place: O(N), no allocation
//
// Lookup: an unordered_map from name to slot, filled once from the member list (names of up to
// 15 characters, SSO: no allocation per lookup). A slot joins the roster when first heard and
// keeps its place (the roster's order is first-heard order; LeaderPlanner does not depend on it).
// Times: simulated seconds of the state (the shared lockstep clock), and optionally the wall
// clock it was received at (netem only, leader_planner.hpp has why). Not thread-safe.
#pragma once

#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "swarmbox/swarm/leader_planner.hpp"

namespace swarmbox::swarm {

class MemberTable {
 public:
  // `members`: every drone of the trial (this one included); `self`: this drone.
  MemberTable(std::span<const std::string> members, std::string self);

  // Word from `name` taken at t_s (simulated) in `mode` at `position_m`; received at wall_s
  // (NaN: no wall clock). Ignored (false) for a non-member, this drone, or a word older than the
  // one held (a reordered message). O(1).
  bool Update(const std::string& name, double t_s, Role role, std::string_view mode,
              const Eigen::Vector2d& position_m, double wall_s = std::numeric_limits<double>::quiet_NaN());
  // This drone, every tick (age 0).
  void UpdateSelf(double t_s, Role role, std::string_view mode, const Eigen::Vector2d& position_m);

  // Every member heard (and this drone once UpdateSelf ran), ages at t_s / wall_s refreshed in
  // place (wall_s NaN: the wall age stays infinite).
  std::span<const RosterEntry> Roster(double t_s, double wall_s = std::numeric_limits<double>::quiet_NaN());

  std::size_t heard() const { return roster_.size(); }  // members heard, this drone included
  // `name` is another member of the mission (not this drone). O(1).
  bool IsPeer(const std::string& name) const { return name != self_ && slot_.count(name) != 0; }
  std::size_t members() const { return slot_.size(); }
  bool lifter_heard() const { return lifters_ > 0; }
  // The entry of `name` (nullptr: not heard yet). Ages as of the last Roster().
  const RosterEntry* Find(const std::string& name) const;

 private:
  struct Heard {
    double t_s = 0.0;
    double wall_s = std::numeric_limits<double>::quiet_NaN();
  };
  RosterEntry* Slot(const std::string& name, Role role);

  std::string self_;
  std::unordered_map<std::string, std::size_t> slot_;  // name -> index in roster_ (npos: unheard)
  std::vector<RosterEntry> roster_;
  std::vector<Heard> heard_;  // beside roster_
  std::size_t lifters_ = 0;
};

}  // namespace swarmbox::swarm
