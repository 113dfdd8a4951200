// ExecuteDockerActions: carries out a process fault's plan (process_plan.hpp) through DockerApi.
// I/O: part of swarmbox_faults, not of the pure fault model.
//
//   ProcessPlan plan = PlanProcessFault(fault, containers, has_duration);
//   SWARMBOX_TRY(ExecuteDockerActions(api, plan.apply));
#pragma once

#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/faults/process_plan.hpp"

namespace swarmbox::faults {

// Runs the actions in order; the first failure stops it, with the action in the message
// ("kill b SIGKILL: <Docker's message>").
Status ExecuteDockerActions(docker::DockerApi& api, const std::vector<DockerAction>& actions);

}  // namespace swarmbox::faults
