// NeighbourTable: the other drones as this agent last heard them on the radio (their DroneState
// broadcasts), and the bounded list a brain gets as brain::Input::neighbours. The per-step cost
// does not grow with the swarm (issue 18: at 20 drones BrainHost rebuilt and copied the whole
// table every step, 250 times a second):
//   - per message (OnState): one O(log N) look-up; the drone's entry is replaced when the state is
//     no older than the one held, and so is its copy in the list when it is listed;
//   - per brain period (List): the list as kept; only every `reselect_ns` of simulated time (and at
//     once after a drone was heard for the first time) is it chosen anew: the drones silent longer
//     than `expire_ns` are forgotten, then the `max_listed` nearest to this drone (3-D, ties by
//     name) are taken, sorted by name. O(N) then, O(1) otherwise.
// So a listed neighbour's state is always its newest; which drones are listed lags their motion
// by at most reselect_ns (200 ms: the state broadcast's period). With max_listed or fewer drones
// heard, every drone is listed (by name), as before the bound.
//
//   NeighbourTable t("scout_1", {.max_listed = 32});
//   t.OnState(state);                                        // every DroneState dispatched
//   in.neighbours = t.List(t_ns, vehicle.position_m);        // every brain period
//
// Pure (no clock: `t_ns` is the step's simulated time); not thread-safe (the control loop).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "swarmbox/brain/brain.hpp"
#include "swarmbox/bus/messages.hpp"

namespace swarmbox::agent {

struct NeighbourTableOptions {
  std::size_t max_listed = 32;               // --brain-neighbours, > 0
  std::int64_t expire_ns = 3'000'000'000;    // silent this long (simulated): forgotten, > 0
  std::int64_t reselect_ns = 200'000'000;    // the nearest set chosen anew this often, > 0
};

class NeighbourTable {
 public:
  // Aborts on a zero max_listed or a non-positive period (a wiring bug: the flags are checked).
  NeighbourTable(std::string self, NeighbourTableOptions options);

  // Another drone's broadcast (our own is ignored). O(log N); allocates only for a new drone.
  void OnState(const bus::DroneState& state);

  // The brain's neighbours at `t_ns` seen from `position_m` (world ENU [m]): at most max_listed,
  // sorted by name, each the newest state heard. Valid until the next OnState or List.
  std::span<const brain::Neighbour> List(std::int64_t t_ns, const brain::Vec3& position_m);

  std::size_t size() const { return table_.size(); }        // drones heard and not expired
  std::uint64_t reselections() const { return reselections_; }
  const NeighbourTableOptions& options() const { return options_; }

 private:
  static constexpr std::size_t kUnlisted = static_cast<std::size_t>(-1);
  struct Slot {
    brain::Neighbour n;
    std::size_t listed = kUnlisted;  // index in list_
  };
  void Reselect(std::int64_t t_ns, const brain::Vec3& position_m);

  std::string self_;
  NeighbourTableOptions options_;
  std::map<std::string, Slot, std::less<>> table_;  // name -> newest (node addresses are stable)
  std::vector<brain::Neighbour> list_;
  std::vector<Slot*> scratch_;
  bool dirty_ = true;  // a new drone: reselect at the next List
  std::int64_t next_reselect_ns_ = 0;
  std::uint64_t reselections_ = 0;
};

}  // namespace swarmbox::agent
