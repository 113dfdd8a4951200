// ResolveTarget: a fault's target -> the drone names it hits when it fires. Pure; the random
// generator is the caller's (seeded from the trial's seed, so a trial replays the same choices).
//
//   std::mt19937_64 rng(trial_seed);
//   auto names = ResolveTarget(fault.target, drones, leaders, rng);   // {"scout_2"}
#pragma once

#include <random>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/faults/fault_spec.hpp"
#include "swarmbox/faults/leader_tracker.hpp"

namespace swarmbox::faults {

// Names in the order of `drones` (kNames: as written). Errors: kNotFound when raft_leader has no
// election yet or a name/pattern matches no drone; kInvalidArgument with no drones at all.
Result<std::vector<std::string>> ResolveTarget(const FaultTarget& target, const std::vector<std::string>& drones,
                                               const LeaderTracker& leaders, std::mt19937_64& rng);

}  // namespace swarmbox::faults
