#include "neighbour_table.hpp"

#include <algorithm>
#include <utility>

#include "brain_convert.hpp"
#include "swarmbox/common/result.hpp"

namespace swarmbox::agent {
namespace {

double Distance2(const brain::Vec3& a, const brain::Vec3& b) {
  const double dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
  return dx * dx + dy * dy + dz * dz;
}

}  // namespace

NeighbourTable::NeighbourTable(std::string self, NeighbourTableOptions options)
    : self_(std::move(self)), options_(options) {
  SWARMBOX_CHECK(options_.max_listed > 0 && options_.expire_ns > 0 && options_.reselect_ns > 0);
}

void NeighbourTable::OnState(const bus::DroneState& state) {
  if (state.drone == self_) return;
  auto it = table_.find(state.drone);
  if (it == table_.end()) {
    table_.emplace(state.drone, Slot{NeighbourFromBus(state), kUnlisted});
    dirty_ = true;
    return;
  }
  Slot& s = it->second;
  if (s.n.t_ns > state.sim_time_ns) return;  // an older one, reordered
  brain::Neighbour& n = s.n;
  n.t_ns = state.sim_time_ns;
  n.position_m = {state.position_enu_m[0], state.position_enu_m[1], state.position_enu_m[2]};
  n.velocity_m_s = {state.velocity_enu_m_s[0], state.velocity_enu_m_s[1], state.velocity_enu_m_s[2]};
  n.heading_rad = state.heading_rad;
  n.battery_fraction = state.battery_fraction;
  n.status = state.mode;  // reuses the string's buffer
  if (s.listed != kUnlisted) list_[s.listed] = n;
}

std::span<const brain::Neighbour> NeighbourTable::List(std::int64_t t_ns, const brain::Vec3& position_m) {
  if (dirty_ || t_ns >= next_reselect_ns_) Reselect(t_ns, position_m);
  return list_;
}

void NeighbourTable::Reselect(std::int64_t t_ns, const brain::Vec3& position_m) {
  ++reselections_;
  dirty_ = false;
  next_reselect_ns_ = t_ns + options_.reselect_ns;
  scratch_.clear();
  for (auto it = table_.begin(); it != table_.end();) {
    if (t_ns - it->second.n.t_ns > options_.expire_ns) {
      it = table_.erase(it);
      continue;
    }
    it->second.listed = kUnlisted;
    scratch_.push_back(&it->second);  // in name order
    ++it;
  }
  if (scratch_.size() > options_.max_listed) {
    auto nearer = [&position_m](const Slot* a, const Slot* b) {
      const double da = Distance2(a->n.position_m, position_m);
      const double db = Distance2(b->n.position_m, position_m);
      return da < db || (da == db && a->n.name < b->n.name);
    };
    const auto cut = scratch_.begin() + static_cast<std::ptrdiff_t>(options_.max_listed);
    std::nth_element(scratch_.begin(), cut, scratch_.end(), nearer);
    scratch_.erase(cut, scratch_.end());
    std::sort(scratch_.begin(), scratch_.end(), [](const Slot* a, const Slot* b) { return a->n.name < b->n.name; });
  }
  list_.resize(scratch_.size());
  for (std::size_t i = 0; i < scratch_.size(); ++i) {
    scratch_[i]->listed = i;
    list_[i] = scratch_[i]->n;
  }
}

}  // namespace swarmbox::agent
