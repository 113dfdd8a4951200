// The swarmbox/e2e-node image: swarmbox-e2e-node (e2e_node.cpp) packed as `swarmbox images` packs
// the programs, into a registry-free image tagged by content hash (built once per binary). Used by
// the runner's e2e tests and by `swarmbox-bench launch` (the engine's floor).
#pragma once

#include <string>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/images/ensure_image.hpp"
#include "swarmbox/images/image_spec.hpp"

namespace swarmbox::testing {

inline constexpr char kE2eNodeInImage[] = "/usr/local/bin/swarmbox-e2e-node";

// `binary`: the host's swarmbox-e2e-node. The image's tag.
inline Result<std::string> EnsureE2eNodeImage(docker::DockerApi& api, const std::string& binary) {
  images::ImageSpec spec;
  spec.repository = "swarmbox/e2e-node";
  spec.component = "e2e-node";
  spec.executables = {{binary, kE2eNodeInImage, 0}};
  spec.entrypoint = {kE2eNodeInImage};
  images::AddSwarmboxBaseFiles(&spec);
  auto image = images::EnsureImage(api, spec, {}, nullptr);
  if (!image) return image.error();
  return image->tag;
}

}  // namespace swarmbox::testing
