// RadioLayers: the radio rules in force on each agent's link, from the network.mesh base and the
// radio faults active on it (applied in order, each composed over the ones below with
// ComposeRadio). Pure bookkeeping for the injector: after each change, plan
// PlanRadioChange(before, after) for the nodes whose rules changed.
//
//   RadioLayers layers(mesh.rules, drones);
//   auto changed = layers.Push("scout_1_fade", {"scout_1"}, fault_rules);   // -> {"scout_1"}
//   auto now = layers.Effective("scout_1");
//   changed = layers.Pop("scout_1_fade");                                    // back to the base
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "swarmbox/faults/netem_spec.hpp"

namespace swarmbox::faults {

class RadioLayers {
 public:
  RadioLayers(std::vector<RadioRule> base, std::vector<std::string> nodes);

  // Adds a layer for `nodes`; returns the nodes whose effective rules changed.
  std::vector<std::string> Push(const std::string& id, const std::vector<std::string>& nodes,
                                std::vector<RadioRule> rules);
  // Removes the layer `id` wherever it is; returns the nodes whose effective rules changed.
  std::vector<std::string> Pop(const std::string& id);
  std::vector<RadioRule> Effective(const std::string& node) const;
  const std::vector<std::string>& nodes() const { return nodes_; }

 private:
  struct Layer {
    std::string id;
    std::vector<RadioRule> rules;
  };
  std::vector<RadioRule> base_;
  std::vector<std::string> nodes_;
  std::map<std::string, std::vector<Layer>> layers_;  // node -> layers in push order
};

}  // namespace swarmbox::faults
