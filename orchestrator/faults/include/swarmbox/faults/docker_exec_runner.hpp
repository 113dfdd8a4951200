// DockerExecCommandRunner: runs plan commands inside a container (the fault sidecar that shares the
// agent's network namespace and alone holds NET_ADMIN) through DockerApi exec.
//
//   DockerExecCommandRunner sidecar(api, "t1-scout_1-faults");
//   SWARMBOX_TRY(RunCommands(sidecar, plan.apply));
#pragma once

#include <string>
#include <vector>

#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/faults/command_runner.hpp"

namespace swarmbox::faults {

class DockerExecCommandRunner : public CommandRunner {
 public:
  DockerExecCommandRunner(docker::DockerApi& api, std::string container)
      : api_(api), container_(std::move(container)) {}
  // Create, start attached (stdout and stderr lines collected), inspect for the exit code. Docker
  // errors come back as they are, with the container in the context.
  Result<CommandOutput> Run(const std::vector<std::string>& argv) override;

 private:
  docker::DockerApi& api_;
  std::string container_;
};

}  // namespace swarmbox::faults
