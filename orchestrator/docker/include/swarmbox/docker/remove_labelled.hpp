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
#include <string_view>
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

// Docker 20.10 can refuse to remove a network with "has active endpoints" though no container is
// attached any more, when several of its containers exited at once (moby#43286; docker-compose
// down hits it too). The endpoint is sometimes released a moment later: RemoveNetworkPatiently
// retries that refusal for ~3 s (waits of 0.1, 0.2, ... 1.6 s) and returns the last status; any
// other result is returned at once. RemoveLabelled removes networks with it.
Status RemoveNetworkPatiently(DockerApi& api, std::string_view id);
// Whether `s` is that refusal. After RemoveNetworkPatiently it lasted: only a dockerd restart
// frees the network; kStaleEndpointAdvice says so to the user.
bool IsStaleEndpointRefusal(const Status& s);
inline constexpr char kStaleEndpointAdvice[] =
    "no container of the trial is attached: Docker 20.10 keeps a stale endpoint, moby#43286, "
    "until dockerd restarts; `swarmbox gc` removes the network then";

}  // namespace swarmbox::docker
