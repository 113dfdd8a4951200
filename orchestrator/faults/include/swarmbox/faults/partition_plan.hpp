// Partition plans: split the mesh into groups with iptables DROP rules on ingress, in each agent's
// namespace (run through that agent's fault sidecar). Pure.
//
//   partition: {groups: [[scout_1, scout_2], [lifter]], oneway: false}
//
// Drones in no group form one more group. Symmetric: every node drops what arrives from nodes of
// other groups. One-way: only traffic FROM groups[0] to the others is cut (nodes outside groups[0]
// drop what comes from groups[0]; groups[0] still hears them). Rules sit in their own chain
// (SWARMBOX-PART-<instance>, hooked from INPUT -i <mesh interface>) so healing removes exactly them;
// dropping on INPUT keeps senders free of EPERM. Nodes that block nobody get no commands.
// Overlapping partitions each get their own chain (SWARMBOX-PART-<instance>, instance = the fault's
// index in the schedule), so healing one leaves the other in place.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/faults/command_runner.hpp"
#include "swarmbox/faults/fault_spec.hpp"

namespace swarmbox::faults {

inline constexpr std::string_view kPartitionChainPrefix = "SWARMBOX-PART-";

struct MeshNode {
  std::string name;            // drone name
  std::string mesh_interface;  // in its namespace, e.g. "eth1"
  std::string ipv4;            // its mesh address
};

struct PartitionPlan {
  std::vector<std::vector<std::string>> groups;            // with the implicit rest group, if any
  std::map<std::string, std::vector<Command>> apply;       // node -> commands in its sidecar
  std::map<std::string, std::vector<Command>> undo;        // node -> commands that heal it
};

// kInvalidArgument for a group member missing from `nodes`, a node in two groups, fewer than two
// groups.
Result<PartitionPlan> PlanPartition(const PartitionFault& partition, const std::vector<MeshNode>& nodes,
                                    std::size_t instance = 0);

}  // namespace swarmbox::faults
