#include "swarmbox/docker/docker_api.hpp"

namespace swarmbox::docker {

Labels SwarmboxLabels(std::string_view run_id, std::string_view trial_id,
                      std::string_view component) {
  return Labels{{std::string(kLabelRun), std::string(run_id)},
                {std::string(kLabelTrial), std::string(trial_id)},
                {std::string(kLabelComponent), std::string(component)}};
}

}  // namespace swarmbox::docker
