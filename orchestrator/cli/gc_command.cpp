// swarmbox gc [--run ID]: remove what killed runs left behind, by label.
#include <iostream>

#include "commands.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/docker/remove_labelled.hpp"

namespace swarmbox::cli {

int GcCommand(const GcArgs& args) {
  docker::DockerClientOptions client_options;
  client_options.socket_path = docker::DefaultSocketPath();
  auto client = docker::DockerClient::Connect(client_options);
  if (!client) {
    std::cerr << "swarmbox gc: " << client.error().ToString() << "\n";
    return kExitInfrastructure;
  }
  docker::LabelSelector selector;
  selector.equals[std::string(docker::kLabelRun)] = args.run_id;  // "" = any run
  auto report = docker::RemoveLabelled(**client, selector, /*include_images=*/false);
  if (!report) {
    std::cerr << "swarmbox gc: " << report.error().ToString() << "\n";
    return kExitInfrastructure;
  }
  std::cout << "removed " << report->containers.size() << " containers and "
            << report->networks.size() << " networks"
            << (args.run_id.empty() ? "" : " of run " + args.run_id) << "\n";
  for (const Error& e : report->failures) std::cerr << "  failed: " << e.ToString() << "\n";
  return report->failures.empty() ? kExitOk : kExitInfrastructure;
}

}  // namespace swarmbox::cli
