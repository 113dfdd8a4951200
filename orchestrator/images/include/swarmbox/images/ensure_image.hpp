// EnsureImage: make sure a host's engine has the image of a spec, building it only when missing.
// What `swarmbox images` and the trial runner call per host.
//
//   auto r = EnsureImage(api, PhysicsImage(binary), [](std::string_view l) { Log(l); }, nullptr);
//   if (!r) return r.error();          // e.g. "image build failed: COPY failed: ..."
//   spec.image = r->tag;               // "swarmbox/physics:3f2a9c01d4e5b6a7"
//
// Errors: packing errors (host files), engine errors from DockerApi, build errors from the build
// stream (errorDetail), each with the image's repository as context.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/images/image_spec.hpp"
#include "swarmbox/images/tag_cache.hpp"

namespace swarmbox::images {

struct EnsuredImage {
  std::string tag;
  std::string image_id;
  bool built = false;               // false: the engine already had this content hash
  std::size_t context_bytes = 0;
  std::int64_t image_size_bytes = 0;
  double pack_s = 0;                // reading files, closure, tar and hash [s]
  double build_s = 0;               // the /build call, 0 when skipped [s]
  bool from_cache = false;          // the tag came from the TagCache (nothing packed; no context)
};

// With a `cache` (tag_cache.hpp), a spec whose input files are unchanged since it was last packed
// is not packed again: its remembered tag is checked on the engine (one inspect) and, when the
// engine has it, that is all; otherwise (or on a miss) it is packed, built if missing, and
// remembered.
Result<EnsuredImage> EnsureImage(docker::DockerApi& api, const ImageSpec& spec,
                                 const docker::BuildProgressFn& progress,
                                 docker::CancelToken* cancel, const TagCache* cache = nullptr);

// Removes the images of `repository` (label swarmbox.image=<repository>, set by the generated
// Dockerfile) other than `keep_tag`: the older content hashes. Not forced, so an image a container
// still uses stays (its failure is skipped). Returns the removed image ids.
Result<std::vector<std::string>> RemoveStaleImages(docker::DockerApi& api,
                                                   const std::string& repository,
                                                   const std::string& keep_tag);

}  // namespace swarmbox::images
