// The netem guest's scenarios: each one is a trial's radio section (a network.mesh block and a
// faults list, as YAML), carried out on a fresh GuestLab by the fault code's own functions on the
// path FaultInjector takes: ParseMeshBlock -> RadioLayers -> PlanRadio(kKernelNetem) for the mesh,
// ParseFaults -> ResolveTarget -> RadioLayers::Push/Pop -> PlanRadioChange for radio faults,
// PlanPartition for partitions. What each applies, measures and lists is reported (guest_console.hpp);
// the host test judges it (netem_guest_test.cpp).
//
//   mesh             50 +- 10 ms normal, 5 % loss on every agent (the userspace test's figures)
//   fixed            fixed 50 ms: the spread of the timer alone
//   per_destination  a radio fault on a: 80 ms and 2000 kbit/s to c only (htb + u32 + netem); b untouched
//   rate             2000 kbit/s on every agent (netem's rate), 1000-byte datagrams
//   reorder          10 ms, 25 % sent at once
//   duplicate        5 ms, 10 % duplicated
//   corrupt          10 % with one bit flipped
//   gilbert_elliott  Gilbert-Elliott loss p 2 % r 25 %: bursts of 4
//   partition        one-way partition a -> b (iptables on b), then healed
//   replace          mesh 20 ms; a per-destination fault and an all-traffic fault pushed and popped;
//                    the mesh plan applied twice; the qdisc tree listed after every step
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "guest_lab.hpp"
#include "swarmbox/common/result.hpp"

namespace swarmbox::netem_guest {

struct Scenario {
  std::string name;
  Status (*run)(GuestLab& lab);
};

const std::vector<Scenario>& AllScenarios();
const Scenario* FindScenario(std::string_view name);

}  // namespace swarmbox::netem_guest
