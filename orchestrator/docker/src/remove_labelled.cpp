#include "swarmbox/docker/remove_labelled.hpp"

#include <chrono>
#include <thread>

namespace swarmbox::docker {

bool IsStaleEndpointRefusal(const Status& s) {
  return !s && s.error().message().find("active endpoints") != std::string::npos;
}

Status RemoveNetworkPatiently(DockerApi& api, std::string_view id) {
  Status s = api.RemoveNetwork(id);
  for (int wait_ms = 100; IsStaleEndpointRefusal(s) && wait_ms <= 1600; wait_ms *= 2) {
    std::this_thread::sleep_for(std::chrono::milliseconds(wait_ms));
    s = api.RemoveNetwork(id);
  }
  return s;
}

Result<RemovalReport> RemoveLabelled(DockerApi& api, const LabelSelector& selector,
                                     bool include_images) {
  if (selector.equals.empty()) {
    return Error(ErrorCode::kInvalidArgument,
                 "refusing to remove by an empty label selector (it matches everything)");
  }
  RemovalReport report;
  auto keep = [&](const Status& s, std::vector<std::string>* done, const std::string& id) {
    if (s || s.error().code() == ErrorCode::kNotFound) {
      done->push_back(id);
    } else {
      report.failures.push_back(s.error());
    }
  };

  auto containers = api.ListContainers(selector, /*all=*/true);
  if (!containers) return containers.error().Context("listing labelled containers");
  for (const ContainerSummary& c : *containers) {
    keep(api.RemoveContainer(c.id, /*force=*/true, /*remove_volumes=*/true), &report.containers, c.id);
  }

  auto networks = api.ListNetworks(selector);
  if (!networks) return networks.error().Context("listing labelled networks");
  for (const NetworkInfo& n : *networks) {
    keep(RemoveNetworkPatiently(api, n.id), &report.networks, n.id);
  }

  if (include_images) {
    auto images = api.ListImages(selector);
    if (!images) return images.error().Context("listing labelled images");
    for (const ImageInfo& i : *images) keep(api.RemoveImage(i.id, /*force=*/true), &report.images, i.id);
  }
  return report;
}

}  // namespace swarmbox::docker
