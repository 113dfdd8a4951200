#include "swarmbox/faults/docker_actions.hpp"

namespace swarmbox::faults {

Status ExecuteDockerActions(docker::DockerApi& api, const std::vector<DockerAction>& actions) {
  for (const auto& a : actions) {
    Status s;
    switch (a.kind) {
      case DockerAction::Kind::kKill: s = api.KillContainer(a.container, a.signal); break;
      case DockerAction::Kind::kStop: s = api.StopContainer(a.container, a.timeout_s); break;
      case DockerAction::Kind::kStart: s = api.StartContainer(a.container); break;
      case DockerAction::Kind::kPause: s = api.PauseContainer(a.container); break;
      case DockerAction::Kind::kUnpause: s = api.UnpauseContainer(a.container); break;
      case DockerAction::Kind::kRestart: s = api.RestartContainer(a.container, a.timeout_s); break;
    }
    if (!s) return s.error().Context(DockerActionText(a));
  }
  return Ok{};
}

}  // namespace swarmbox::faults
