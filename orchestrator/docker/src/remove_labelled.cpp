#include "swarmbox/docker/remove_labelled.hpp"

namespace swarmbox::docker {

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
    keep(api.RemoveNetwork(n.id), &report.networks, n.id);
  }

  if (include_images) {
    auto images = api.ListImages(selector);
    if (!images) return images.error().Context("listing labelled images");
    for (const ImageInfo& i : *images) keep(api.RemoveImage(i.id, /*force=*/true), &report.images, i.id);
  }
  return report;
}

}  // namespace swarmbox::docker
