// Process faults as plans of Docker calls: kill (a signal), stop/start, pause/unpause, restart,
// planned purely here and carried out through DockerApi by ExecuteDockerActions
// (docker_actions.hpp, I/O).
//
//   auto targets = ResolveTarget(fault.target, drones, leaders, rng);     // target_resolver.hpp
//   ProcessPlan plan = PlanProcessFault(fault, ContainersOf(*targets), has_duration);
//   SWARMBOX_TRY(ExecuteDockerActions(api, plan.apply));
//   ... after the duration: ExecuteDockerActions(api, plan.undo);
//
// Undo: kill and stop are undone by start, pause by unpause; restart has no undo; without a
// duration the undo list is empty (the container stays down until the trial ends).
#pragma once

#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/faults/fault_spec.hpp"

namespace swarmbox::faults {

struct DockerAction {
  enum class Kind { kKill, kStop, kStart, kPause, kUnpause, kRestart };
  Kind kind = Kind::kKill;
  std::string container;   // id or name
  std::string signal;      // kKill
  int timeout_s = 0;       // kStop, kRestart
  bool operator==(const DockerAction&) const = default;
};

// "kill scout_1 SIGKILL", "stop scout_1 (timeout 10s)", ...
std::string DockerActionText(const DockerAction& action);

struct ProcessPlan {
  std::vector<DockerAction> apply;
  std::vector<DockerAction> undo;
};

ProcessPlan PlanProcessFault(const ProcessFault& fault, const std::vector<std::string>& containers,
                             bool has_duration);

}  // namespace swarmbox::faults
