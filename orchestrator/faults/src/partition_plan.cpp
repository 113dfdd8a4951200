#include "swarmbox/faults/partition_plan.hpp"

#include <algorithm>
#include <set>

namespace swarmbox::faults {

Result<PartitionPlan> PlanPartition(const PartitionFault& partition, const std::vector<MeshNode>& nodes,
                                    std::size_t instance) {
  PartitionPlan plan;
  std::map<std::string, const MeshNode*> by_name;
  for (const auto& n : nodes) by_name[n.name] = &n;
  std::map<std::string, std::size_t> group_of;
  for (std::size_t g = 0; g < partition.groups.size(); ++g) {
    for (const auto& name : partition.groups[g]) {
      if (by_name.find(name) == by_name.end()) {
        return Error(ErrorCode::kInvalidArgument, "partition names unknown drone '" + name + "'");
      }
      if (!group_of.emplace(name, g).second) {
        return Error(ErrorCode::kInvalidArgument, "drone '" + name + "' is in two partition groups");
      }
    }
  }
  plan.groups = partition.groups;
  std::vector<std::string> rest;
  for (const auto& n : nodes) {
    if (group_of.find(n.name) == group_of.end()) rest.push_back(n.name);
  }
  if (!rest.empty()) {
    for (const auto& name : rest) group_of[name] = plan.groups.size();
    plan.groups.push_back(rest);
  }
  if (plan.groups.size() < 2) {
    return Error(ErrorCode::kInvalidArgument,
                 "a partition needs at least two groups (drones in no group form one more)");
  }

  const std::string chain = std::string(kPartitionChainPrefix) + std::to_string(instance);
  for (const auto& node : nodes) {
    const std::size_t mine = group_of.at(node.name);
    std::vector<const MeshNode*> blocked;
    for (const auto& peer : nodes) {
      const std::size_t theirs = group_of.at(peer.name);
      if (theirs == mine) continue;
      // One-way: only what comes from groups[0] is dropped, by the nodes of the other groups.
      if (partition.oneway && theirs != 0) continue;
      blocked.push_back(&peer);
    }
    if (blocked.empty()) continue;
    auto& apply = plan.apply[node.name];
    apply.push_back(Command{{"iptables", "-w", "-N", chain}, false});
    for (const MeshNode* peer : blocked) {
      apply.push_back(Command{{"iptables", "-w", "-A", chain, "-s", peer->ipv4 + "/32", "-j", "DROP"}, false});
    }
    apply.push_back(Command{{"iptables", "-w", "-I", "INPUT", "-i", node.mesh_interface, "-j", chain}, false});
    plan.undo[node.name] = {
        Command{{"iptables", "-w", "-D", "INPUT", "-i", node.mesh_interface, "-j", chain}, false},
        Command{{"iptables", "-w", "-F", chain}, false},
        Command{{"iptables", "-w", "-X", chain}, false},
    };
  }
  return plan;
}

}  // namespace swarmbox::faults
