// The fault sidecar's image for a run: the fault tools (tc, iptables) plus the host-built
// swarmbox-netemd (images::FaultSidecarImage), built on the engine only when its content hash is
// missing. RunTrialSpec calls it when a trial impairs the mesh and RunOptions::images.faults is "".
//
//   auto tag = EnsureFaultsImage(api, FindNetemd(""), progress);   // "swarmbox/faults:3f2a..."
#pragma once

#include <functional>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"

namespace swarmbox::runner {

// swarmbox-netemd on this machine, in order: `explicit_path` (must be executable), then
// $SWARMBOX_BIN_DIR/swarmbox-netemd, the build tree of the running program (<build>/orchestrator/
// faults/swarmbox-netemd, looked for from the program's folder up to four levels), then $PATH.
// kNotFound listing every place looked at.
Result<std::string> FindNetemd(const std::string& explicit_path);

// The image tag; errors from packing (a fault tool missing on this host) or the engine's build.
Result<std::string> EnsureFaultsImage(docker::DockerApi& api, const std::string& netemd_binary,
                                      const std::function<void(std::string_view)>& progress);

}  // namespace swarmbox::runner
