#include "connect_engine.hpp"

#include <iostream>

#include "commands.hpp"
#include "swarmbox/docker/engine_endpoint.hpp"

namespace swarmbox::cli {

EngineConnection ConnectEngineOrPrintError(std::string_view command) {
  EngineConnection c;
  auto engine = docker::EngineEndpointFromEnvironment();
  if (!engine) {
    std::cerr << "swarmbox " << command << ": " << engine.error().ToString() << "\n";
    c.exit_code = kExitUsage;
    return c;
  }
  docker::DockerClientOptions options;
  options.engine = *engine;
  auto client = docker::DockerClient::Connect(options);
  if (!client) {
    std::cerr << "swarmbox " << command << ": " << client.error().ToString() << "\n";
    c.exit_code = kExitInfrastructure;
    return c;
  }
  c.client = std::move(*client);
  return c;
}

}  // namespace swarmbox::cli
