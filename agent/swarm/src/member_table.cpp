#include "swarmbox/swarm/member_table.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace swarmbox::swarm {
namespace {

constexpr std::size_t kUnheard = static_cast<std::size_t>(-1);

}  // namespace

MemberTable::MemberTable(std::span<const std::string> members, std::string self) : self_(std::move(self)) {
  slot_.reserve(members.size() + 1);
  for (const std::string& m : members) slot_.emplace(m, kUnheard);
  slot_.emplace(self_, kUnheard);
  roster_.reserve(slot_.size());
  heard_.reserve(slot_.size());
}

RosterEntry* MemberTable::Slot(const std::string& name, Role role) {
  const auto it = slot_.find(name);
  if (it == slot_.end()) return nullptr;
  if (it->second == kUnheard) {
    it->second = roster_.size();
    RosterEntry e;
    e.name = name;
    e.role = role;
    roster_.push_back(std::move(e));
    heard_.push_back({});
    if (role == Role::kLifter) ++lifters_;
  }
  return &roster_[it->second];
}

bool MemberTable::Update(const std::string& name, double t_s, Role role, std::string_view mode,
                         const Eigen::Vector2d& position_m, double wall_s) {
  if (name == self_) return false;
  const auto it = slot_.find(name);
  if (it == slot_.end()) return false;
  if (it->second != kUnheard && t_s < heard_[it->second].t_s) return false;  // older than held
  RosterEntry* e = Slot(name, role);
  Heard& h = heard_[it->second];
  if (e->role != role) {  // a role never changes in a trial; keep the lifter count true anyway
    lifters_ = lifters_ - (e->role == Role::kLifter ? 1 : 0) + (role == Role::kLifter ? 1 : 0);
    e->role = role;
  }
  if (e->mode != mode) e->mode.assign(mode);
  e->position_m = position_m;
  h.t_s = t_s;
  h.wall_s = wall_s;
  return true;
}

void MemberTable::UpdateSelf(double t_s, Role role, std::string_view mode,
                             const Eigen::Vector2d& position_m) {
  RosterEntry* e = Slot(self_, role);
  const std::size_t i = slot_.find(self_)->second;
  if (e->role != role) {
    lifters_ = lifters_ - (e->role == Role::kLifter ? 1 : 0) + (role == Role::kLifter ? 1 : 0);
    e->role = role;
  }
  if (e->mode != mode) e->mode.assign(mode);
  e->position_m = position_m;
  heard_[i].t_s = t_s;
  heard_[i].wall_s = std::numeric_limits<double>::quiet_NaN();
}

std::span<const RosterEntry> MemberTable::Roster(double t_s, double wall_s) {
  for (std::size_t i = 0; i < roster_.size(); ++i) {
    RosterEntry& e = roster_[i];
    if (e.name == self_) {
      e.age_s = 0.0;
      e.wall_age_s = 0.0;
      continue;
    }
    // Age on the shared simulated clock (lockstep): see leader_planner.hpp for the timeout.
    e.age_s = std::max(0.0, t_s - heard_[i].t_s);
    // And, netem only, on the wall clock since it was received (infinite without).
    const double wall_age_s = wall_s - heard_[i].wall_s;
    e.wall_age_s =
        std::isfinite(wall_age_s) ? std::max(0.0, wall_age_s) : std::numeric_limits<double>::infinity();
  }
  return roster_;
}

const RosterEntry* MemberTable::Find(const std::string& name) const {
  const auto it = slot_.find(name);
  if (it == slot_.end() || it->second == kUnheard) return nullptr;
  return &roster_[it->second];
}

}  // namespace swarmbox::swarm
