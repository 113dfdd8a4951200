// Files into and out of a container through Docker's archive endpoint (so remote engines work
// too): the input files and scratch directories copied in before a container starts, and the
// artifacts collected after it stopped. Used by DockerEngine; no state of their own.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/dsl/plugin.hpp"

namespace swarmbox::runner {

// Puts spec.inputs (read from the host) and spec.scratch_dirs (mode 1777) into the created
// container: one archive at "/" for a writable root filesystem, else one per volume (a read-only
// root filesystem takes archives in its volumes only; a path in none of them is kInvalidArgument).
Status CopyInputs(docker::DockerApi& api, const dsl::ContainerSpec& spec,
                  const std::string& container_id);

struct CollectedArtifacts {
  // File name relative to the trial folder ("truth.csv", "components/recorder/out.csv") -> path
  // on the host.
  std::map<std::string, std::string> files;
  // What went wrong without changing the outcome ("<component>: artifact <path> not collected: ...").
  std::vector<std::string> problems;
};

// Fetches each path of `artifacts` from the (stopped) container into `trial_dir`: by file name
// when `artifacts_dir` is empty, else under trial_dir/artifacts_dir keeping a folder's layout.
CollectedArtifacts CollectArtifacts(docker::DockerApi& api, const std::string& container_id,
                                    const std::string& component,
                                    const std::vector<std::string>& artifacts,
                                    const std::string& trial_dir, const std::string& artifacts_dir);

}  // namespace swarmbox::runner
