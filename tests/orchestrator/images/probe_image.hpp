// The image of the e2e probe program (swarmbox_docker_probe, probe_main.cpp), built and run by the
// docker e2e tests and by the images bench. The including target defines SWARMBOX_PROBE_PATH, the
// probe's path in the build tree.
#pragma once

#include "swarmbox/images/image_spec.hpp"

namespace swarmbox::testing {

inline images::ImageSpec ProbeImageSpec() {
  images::ImageSpec spec;
  spec.repository = "swarmbox/e2e-probe";
  spec.component = "e2e-probe";
  spec.executables.push_back({SWARMBOX_PROBE_PATH, "/usr/local/bin/swarmbox-probe", 0755});
  spec.entrypoint = {"/usr/local/bin/swarmbox-probe"};
  images::AddSwarmboxBaseFiles(&spec);
  return spec;
}

}  // namespace swarmbox::testing
