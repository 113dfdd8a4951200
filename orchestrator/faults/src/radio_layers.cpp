#include "swarmbox/faults/radio_layers.hpp"

#include <algorithm>

#include "swarmbox/faults/radio_plan.hpp"

namespace swarmbox::faults {

RadioLayers::RadioLayers(std::vector<RadioRule> base, std::vector<std::string> nodes)
    : base_(std::move(base)), nodes_(std::move(nodes)) {}

std::vector<RadioRule> RadioLayers::Effective(const std::string& node) const {
  std::vector<RadioRule> rules = base_;
  if (auto it = layers_.find(node); it != layers_.end()) {
    for (const Layer& l : it->second) rules = ComposeRadio(rules, l.rules);
  }
  return rules;
}

std::vector<std::string> RadioLayers::Push(const std::string& id, const std::vector<std::string>& nodes,
                                           std::vector<RadioRule> rules) {
  std::vector<std::string> changed;
  for (const auto& node : nodes) {
    const auto before = Effective(node);
    layers_[node].push_back(Layer{id, rules});
    if (Effective(node) != before) changed.push_back(node);
  }
  return changed;
}

std::vector<std::string> RadioLayers::Pop(const std::string& id) {
  std::vector<std::string> changed;
  for (auto& [node, stack] : layers_) {
    const auto before = Effective(node);
    const auto old_size = stack.size();
    std::erase_if(stack, [&](const Layer& l) { return l.id == id; });
    if (stack.size() != old_size && Effective(node) != before) changed.push_back(node);
  }
  return changed;
}

}  // namespace swarmbox::faults
