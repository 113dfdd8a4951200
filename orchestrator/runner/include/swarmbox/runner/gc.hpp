// `swarmbox gc`: removes whatever a killed orchestrator left behind, found by label
// (swarmbox.run present, or swarmbox.run=<id> for one run): containers first (forced, with their
// anonymous volumes), then networks.
#pragma once

#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"

namespace swarmbox::runner {

struct GcReport {
  std::vector<std::string> containers;  // names removed
  std::vector<std::string> networks;    // names removed
  std::vector<std::string> failures;    // "<name>: <error>"
};

// run_id "" = every run. Errors only when the engine cannot be listed.
Result<GcReport> CollectGarbage(docker::DockerApi& api, const std::string& run_id = {});

}  // namespace swarmbox::runner
