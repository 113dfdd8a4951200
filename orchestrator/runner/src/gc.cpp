#include "swarmbox/runner/gc.hpp"

namespace swarmbox::runner {

Result<GcReport> CollectGarbage(docker::DockerApi& api, const std::string& run_id) {
  docker::LabelSelector selector;
  selector.equals[std::string(docker::kLabelRun)] = run_id;  // "" = label present
  GcReport report;
  auto containers = api.ListContainers(selector, /*all=*/true);
  if (!containers) return containers.error().Context("listing SwarmBox containers");
  for (const docker::ContainerSummary& c : *containers) {
    const std::string name = c.names.empty() ? c.id : c.names.front();
    if (Status s = api.RemoveContainer(c.id, /*force=*/true, /*remove_volumes=*/true);
        !s && s.error().code() != ErrorCode::kNotFound) {
      report.failures.push_back(name + ": " + s.error().ToString());
    } else {
      report.containers.push_back(name);
    }
  }
  auto networks = api.ListNetworks(selector);
  if (!networks) return networks.error().Context("listing SwarmBox networks");
  for (const docker::NetworkInfo& n : *networks) {
    if (Status s = api.RemoveNetwork(n.id); !s && s.error().code() != ErrorCode::kNotFound) {
      report.failures.push_back(n.name + ": " + s.error().ToString());
    } else {
      report.networks.push_back(n.name);
    }
  }
  return report;
}

}  // namespace swarmbox::runner
