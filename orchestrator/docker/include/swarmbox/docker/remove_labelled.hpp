// RemoveLabelled: remove everything in an engine that carries given labels: the basis of
// `swarmbox gc` (ARCHITECTURE.md "Labels": everything SwarmBox creates carries swarmbox.run,
// swarmbox.trial and swarmbox.component).
//
//   LabelSelector run;
//   run.equals = {{std::string(kLabelRun), run_id}};
//   auto report = RemoveLabelled(api, run, /*include_images=*/false);
//
// Order: containers (forced: running ones are killed; anonymous volumes go too), then networks,
// then, when asked, images. Keeps going past single failures (a container removed meanwhile is
// not a failure) and lists them in the report; returns an Error only when a listing fails. An
// empty selector is refused (kInvalidArgument): it would match everything SwarmBox did not create.
#pragma once

#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"

namespace swarmbox::docker {

struct RemovalReport {
  std::vector<std::string> containers;  // ids removed
  std::vector<std::string> networks;
  std::vector<std::string> images;
  std::vector<Error> failures;
};

Result<RemovalReport> RemoveLabelled(DockerApi& api, const LabelSelector& selector,
                                     bool include_images);

}  // namespace swarmbox::docker
