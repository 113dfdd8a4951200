// The images a trial runs: the physics server and the agent, packed from the host-built programs
// (registry-free, see swarmbox/images). Finding the programs, in order:
//   1. the path given on the command line (--physics-bin / --agent-bin), which must exist;
//   2. $SWARMBOX_BIN_DIR/<program>;
//   3. the build tree this swarmbox was built in: <build>/physics_server/[app/]swarmbox-physics,
//      <build>/agent/[app/]swarmbox-agent (swarmbox itself is <build>/orchestrator/cli/swarmbox);
//   4. beside the running swarmbox (an installed prefix: <prefix>/bin/swarmbox-physics);
//   5. $PATH.
#pragma once

#include <functional>
#include <string>
#include <string_view>

#include "commands.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/runner/plan.hpp"

namespace swarmbox::cli {

// kNotFound listing every place looked at.
Result<std::string> FindProgram(std::string_view program, const std::string& explicit_path);

// Makes sure the engine has both images (building what is missing); returns their tags.
Result<runner::Images> EnsureTrialImages(docker::DockerApi& api, const ProgramPaths& programs,
                                         const std::function<void(std::string_view)>& progress);

// The tags the programs pack to, without an engine (for `swarmbox compose`).
Result<runner::Images> TrialImageTags(const ProgramPaths& programs);

}  // namespace swarmbox::cli
