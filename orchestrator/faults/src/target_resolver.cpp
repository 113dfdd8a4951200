#include "swarmbox/faults/target_resolver.hpp"

#include <fnmatch.h>

#include <algorithm>

namespace swarmbox::faults {

Result<std::vector<std::string>> ResolveTarget(const FaultTarget& target, const std::vector<std::string>& drones,
                                               const LeaderTracker& leaders, std::mt19937_64& rng) {
  if (drones.empty()) return Error(ErrorCode::kInvalidArgument, "the trial has no drones to target");
  switch (target.kind) {
    case FaultTarget::Kind::kAll: return drones;
    case FaultTarget::Kind::kRaftLeader: {
      auto leader = leaders.Resolve();
      if (!leader) return leader.error();
      if (std::find(drones.begin(), drones.end(), *leader) == drones.end()) {
        return Error(ErrorCode::kNotFound, "the Raft leader '" + *leader + "' is not a drone of this trial");
      }
      return std::vector<std::string>{*leader};
    }
    case FaultTarget::Kind::kRandom: {
      // rng() % n rather than uniform_int_distribution, whose algorithm the standard leaves open:
      // the same seed picks the same drone with any standard library.
      return std::vector<std::string>{drones[static_cast<std::size_t>(rng() % drones.size())]};
    }
    case FaultTarget::Kind::kPattern: {
      std::vector<std::string> out;
      for (const auto& d : drones) {
        if (fnmatch(target.pattern.c_str(), d.c_str(), 0) == 0) out.push_back(d);
      }
      if (out.empty()) return Error(ErrorCode::kNotFound, "pattern '" + target.pattern + "' matches no drone");
      return out;
    }
    case FaultTarget::Kind::kNames: {
      for (const auto& n : target.names) {
        if (std::find(drones.begin(), drones.end(), n) == drones.end()) {
          return Error(ErrorCode::kNotFound, "no drone named '" + n + "'");
        }
      }
      return target.names;
    }
  }
  return Error(ErrorCode::kInternal, "unhandled target kind");
}

}  // namespace swarmbox::faults
