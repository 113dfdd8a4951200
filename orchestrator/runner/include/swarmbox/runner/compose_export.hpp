// `swarmbox compose`: a trial's tree as a docker-compose file (format 2.4, which Debian's
// docker-compose 1.29 runs), for poking at one trial by hand:
//   - the trial's networks with their subnets and gateways (ipam), internal, labels
//   - one service per container: same image, argv (entrypoint + command), environment, labels,
//     hostname, fixed addresses and aliases on each network
//   - start order (run priority) as depends_on: each service depends on the services of the
//     previous priority level
//   - a user's image keeps its entrypoint (`command` only); a Dockerfile's image is `build:`
//   - input files bind-mounted read-only (the runner copies them in through the API instead),
//     scratch dirs (/out) as tmpfs with mode 1777 (the images run as uid 1000)
// Pure: the text is returned; the CLI writes it.
#pragma once

#include <map>
#include <string>

#include "swarmbox/dsl/trial.hpp"

namespace swarmbox::runner {

struct ComposeOptions {
  // Host paths of input files that start with `host_prefix` are written with `relative_prefix`
  // instead (e.g. /work/main/trials -> ../trials, for a file kept in compose/).
  std::string host_prefix;
  std::string relative_prefix;
  std::string header_comment;  // first lines of the file, each prefixed with "# "
  // Services whose image compose builds (a brain's or component's Dockerfile): service id ->
  // the context folder and the Dockerfile in it.
  struct Build {
    std::string context;
    std::string dockerfile;
  };
  std::map<std::string, Build> builds;
};

std::string ComposeYaml(dsl::Trial& trial, const ComposeOptions& options);

}  // namespace swarmbox::runner
