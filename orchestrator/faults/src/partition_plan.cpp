#include "swarmbox/faults/partition_plan.hpp"

#include <algorithm>
#include <set>

namespace swarmbox::faults {

namespace {

// Drone name -> index of its group in plan.groups.
using GroupOf = std::map<std::string, std::size_t>;

// The given groups, each drone in at most one and every one a known node; the rest of the nodes
// form one more group at the end.
Result<GroupOf> AssignGroups(const PartitionFault& partition, const std::vector<MeshNode>& nodes,
                             PartitionPlan& plan) {
  std::map<std::string, const MeshNode*> by_name;
  for (const auto& n : nodes) by_name[n.name] = &n;
  GroupOf group_of;
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
  return group_of;
}

// The peers whose packets `node` drops.
std::vector<const MeshNode*> BlockedPeers(const MeshNode& node, const std::vector<MeshNode>& nodes,
                                          const GroupOf& group_of, bool oneway) {
  const std::size_t mine = group_of.at(node.name);
  std::vector<const MeshNode*> blocked;
  for (const auto& peer : nodes) {
    const std::size_t theirs = group_of.at(peer.name);
    if (theirs == mine) continue;
    // One-way: only what comes from groups[0] is dropped, by the nodes of the other groups.
    if (oneway && theirs != 0) continue;
    blocked.push_back(&peer);
  }
  return blocked;
}

// Fills plan.apply and plan.undo for a node that blocks `blocked`: its own chain of DROP rules,
// hooked from INPUT on the mesh interface.
void AddNodeRules(const MeshNode& node, const std::vector<const MeshNode*>& blocked, const std::string& chain,
                  PartitionPlan& plan) {
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

}  // namespace

Result<PartitionPlan> PlanPartition(const PartitionFault& partition, const std::vector<MeshNode>& nodes,
                                    std::size_t instance) {
  PartitionPlan plan;
  auto group_of = AssignGroups(partition, nodes, plan);
  if (!group_of) return group_of.error();
  if (plan.groups.size() < 2) {
    return Error(ErrorCode::kInvalidArgument,
                 "a partition needs at least two groups (drones in no group form one more)");
  }
  const std::string chain = std::string(kPartitionChainPrefix) + std::to_string(instance);
  for (const auto& node : nodes) {
    const std::vector<const MeshNode*> blocked = BlockedPeers(node, nodes, *group_of, partition.oneway);
    if (!blocked.empty()) AddNodeRules(node, blocked, chain, plan);
  }
  return plan;
}

}  // namespace swarmbox::faults
