// The Docker engine of `swarmbox run`, `images` and `gc`: where $DOCKER_HOST (and
// $DOCKER_TLS_VERIFY, $DOCKER_CERT_PATH) point, as the docker CLI reads them
// (docker/engine_endpoint.hpp); /var/run/docker.sock when unset.
#pragma once

#include <memory>
#include <string_view>

#include "swarmbox/docker/docker_client.hpp"

namespace swarmbox::cli {

struct EngineConnection {
  std::unique_ptr<docker::DockerClient> client;  // null on failure
  int exit_code = 0;                             // kExitUsage (bad $DOCKER_HOST) or kExitInfrastructure
};

// Connects, or prints "swarmbox <command>: <why>" on stderr and says which exit code fits.
EngineConnection ConnectEngineOrPrintError(std::string_view command);

}  // namespace swarmbox::cli
