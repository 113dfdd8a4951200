// The images of a trial's own software (drones[].brain, components:), registry-free like the rest:
//
//   library brain   the agent image plus the library (and its shared-library closure) at
//                   /swarmbox/brains/<basename>: AgentWithBrainImage, repository swarmbox/agent-brain.
//                   A derived image rather than a copy into the container at start: the packer
//                   brings the library's closure along (the archive copy would not), the content
//                   hash names it (unchanged = not rebuilt), and `swarmbox compose` runs it as is.
//   program         the host binary with its closure in a FROM scratch image, entrypoint
//                   /usr/local/bin/<basename>, user 1000 (ProgramImage; brains swarmbox/brain,
//                   components swarmbox/component); the parents of a component's `collect:`
//                   paths are made world-writable folders in it (so the program can write them).
//   dockerfile      built through the Engine API with the Dockerfile's folder as the context (a
//                   deterministic tar; tag swarmbox/user-<name>:<context hash>, built only when
//                   missing). Nothing is pulled: the Dockerfile may only build FROM images on the
//                   engine (the build error says so).
//   image           must be on the engine already (inspected; never pulled).
//
//   auto images = EnsureUserImages(api, spec, agent_binary, base, progress, &cache);
//   options.images = *images;   // base + drone_agents, brains, components
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/dsl/trial_spec.hpp"
#include "swarmbox/images/image_spec.hpp"
#include "swarmbox/images/tag_cache.hpp"
#include "swarmbox/runner/plan.hpp"

namespace swarmbox::runner {

inline constexpr char kAgentBrainRepository[] = "swarmbox/agent-brain";
inline constexpr char kBrainRepository[] = "swarmbox/brain";
inline constexpr char kComponentRepository[] = "swarmbox/component";

// Pure: the ImageSpecs (the packer reads the files).
images::ImageSpec AgentWithBrainImage(const std::string& agent_binary, const std::string& library);
images::ImageSpec ProgramImage(const std::string& repository, const std::string& component,
                               const std::string& binary, const std::vector<std::string>& collect = {});

// A Dockerfile's build context: its folder as a deterministic tar (sorted, mtime 0, owner 0,
// modes kept; symlinks kept as links) and the tag it builds to.
struct DockerfileContext {
  std::string tar;
  std::string dockerfile;  // its path inside the context
  std::string tag;         // "swarmbox/user-<name>:<first 16 hex digits of the context's SHA-256>"
};
Result<DockerfileContext> PackDockerfileContext(const std::string& dockerfile, std::string_view name);

// The tag of a Dockerfile's image, built when the engine does not have it (no pull; the error
// says that only local images can be used FROM).
Result<std::string> EnsureDockerfileImage(docker::DockerApi& api, const std::string& dockerfile,
                                          std::string_view name,
                                          const std::function<void(std::string_view)>& progress);

// `base` (physics, agent) plus every image the trial's brains and components need, made on the
// engine when missing. `agent_binary`: the host swarmbox-agent (library brains only).
Result<Images> EnsureUserImages(docker::DockerApi& api, const dsl::TrialSpec& spec,
                                const std::string& agent_binary, Images base,
                                const std::function<void(std::string_view)>& progress,
                                const images::TagCache* cache = nullptr);

// The same tags without an engine (`swarmbox compose`): packed contexts' hashes; a Dockerfile's
// image is its context tag (compose builds it itself from `build:`), an image its reference.
Result<Images> UserImageTags(const dsl::TrialSpec& spec, const std::string& agent_binary, Images base);

}  // namespace swarmbox::runner
