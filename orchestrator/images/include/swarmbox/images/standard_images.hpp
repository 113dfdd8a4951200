// The three images SwarmBox runs, as ImageSpecs for EnsureImage: the physics server, the agent and
// the fault-injection sidecar. `swarmbox images` and the runner call these with the host-built
// binaries' paths.
//
//   auto faults = FaultToolsImage();          // tc + iptables (nft) with plugins, from this host
//   if (!faults) return faults.error();       // e.g. "no '*.so' plugin in the directory"
//   EnsureImage(api, *faults, progress, nullptr);
//
// Physics and agent run as the non-root user 1000 (`swarmbox`). The fault sidecar is the one
// exception: its image's USER is 0, and the runner must create it with CapDrop ALL and CapAdd
// NET_ADMIN only, sharing the agent's network namespace ("container:<agent>"); the agents stay
// unprivileged. Why root: Docker 20.10 grants no ambient capabilities to a non-root user, and the
// other way (a security.capability file capability on tc/xtables) does not survive its builder:
// measured, the xattr is in the build context but not in the image layer, also with the docker
// CLI's own context.
#pragma once

#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/images/image_spec.hpp"

namespace swarmbox::images {

inline constexpr char kPhysicsRepository[] = "swarmbox/physics";
inline constexpr char kAgentRepository[] = "swarmbox/agent";
inline constexpr char kFaultsRepository[] = "swarmbox/faults";
inline constexpr char kPhysicsBinaryInImage[] = "/usr/local/bin/swarmbox-physics";
inline constexpr char kAgentBinaryInImage[] = "/usr/local/bin/swarmbox-agent";

// `binary`: the host-built swarmbox-physics / swarmbox-agent. The binary becomes the entrypoint.
ImageSpec PhysicsImage(const std::string& binary);
ImageSpec AgentImage(const std::string& binary);

// Where this host keeps the fault tools (Debian 12 defaults).
struct FaultToolPaths {
  std::string tc = "/usr/sbin/tc";
  std::string xtables_multi = "/usr/sbin/xtables-nft-multi";
  std::string xtables_plugin_dir = "/usr/lib/x86_64-linux-gnu/xtables";
  // More host programs for the sidecar (e.g. the userspace impairment daemon for kernels without
  // sch_netem), packed with their closure.
  std::vector<HostFile> extra_programs;
};

// tc, iptables/ip6tables(-save/-restore) as links to xtables-nft-multi, the xtables plugins (not
// listed by ldd), /run and /tmp. No entrypoint: the injector runs commands with exec. kNotFound
// when a tool or the plugin directory is missing on this host.
Result<ImageSpec> FaultToolsImage(const FaultToolPaths& paths = {});

// Where the fault sidecar finds the userspace delayer (the runner's radio plans call it there).
inline constexpr char kNetemdInImage[] = "/usr/bin/swarmbox-netemd";

// The image of the runner's fault sidecars: FaultToolsImage plus the host-built swarmbox-netemd at
// kNetemdInImage (the userspace mechanism for kernels without sch_netem; also the sidecar's pid 1,
// `swarmbox-netemd sleep`). kNotFound when `netemd_binary` is not an executable file.
Result<ImageSpec> FaultSidecarImage(const std::string& netemd_binary, FaultToolPaths paths = {});

}  // namespace swarmbox::images
