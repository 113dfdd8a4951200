// Radio plans: a NetemSpec (as RadioRules) + the target's mesh link + a Mechanism -> the exact,
// ordered argv lists that apply the impairment and that undo it. Pure: nothing runs here.
//
//   LinkTarget link{.node = "scout_1", .mesh_interface = "eth1",
//                   .peer_ipv4 = {{"scout_2", "10.77.2.11"}, {"lifter", "10.77.2.12"}}};
//   auto plan = PlanRadio(rules, link, Mechanism::kUserspace, {.seed = trial_seed});
//   if (!plan) return plan.error();              // e.g. the mechanism cannot do `duplicate`
//   SWARMBOX_TRY(RunCommands(sidecar, plan->apply));
//   ... later: RunAllCommands(sidecar, plan->undo);
//
// Only `mesh_interface` is ever touched (the sim link never is).
//
// Kernel netem (egress of the target's mesh interface):
//   all traffic:   tc qdisc replace dev IF root netem limit L delay ... loss ... rate ...
//   per-destination rules: tc qdisc replace dev IF root handle 1: htb default 1; class 1:1 (the
//                  all-traffic rule's netem, or none) and one class 1:1N + netem per rule, u32
//                  filters on `ip dst` per peer.
//   undo:          tc qdisc del dev IF root
// Userspace (no sch_netem):
//   delay/jitter/reorder (and Gilbert-Elliott loss, dropped by the daemon, and corruption, a bit
//                  flipped by the daemon) on egress:
//                  swarmbox-netemd per rule (NFQUEUE number first_queue + i,
//                  started first), then chain SWARMBOX-RADIO-OUT (-d PEER for per-destination
//                  rules, RETURN for peers whose rule has no delay) hooked from OUTPUT -o IF with
//                  NFQUEUE --queue-bypass (traffic flows undelayed if the daemon dies);
//   duplicate:     in SWARMBOX-RADIO-OUT before the rule's NFQUEUE, -d PEER -m statistic --mode
//                  random --probability P -j TEE --gateway PEER (every known peer for the
//                  all-traffic rule; multicast is not duplicated): the clone passes OUTPUT again,
//                  is not cloned again, and gets its own delay from the daemon, as netem's does.
//   loss on ingress: chain SWARMBOX-RADIO-IN hooked from INPUT -i IF, -m statistic --mode random
//                  --probability P -j DROP (-s PEER per destination): on ingress the sender never sees
//                  EPERM. So for one target, delay acts on what it sends and loss on what it
//                  receives; for the mesh-wide block (every agent) each packet crosses one of each,
//                  as with netem.
//   rate:          tc qdisc replace dev IF root tbf (all traffic), or htb classes with rate and u32
//                  filters per destination.
//   undo:          hooks removed, chains flushed and deleted, daemons stopped, root qdisc deleted.
//
// netem's queue `limit` (and the daemon's queue length) is raised from the default 1000 packets
// when delay x rate needs it: 2 x rate x (delay + 4 jitter) / kAssumedPacketBytes.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/faults/command_runner.hpp"
#include "swarmbox/faults/mechanism.hpp"
#include "swarmbox/faults/netem_spec.hpp"

namespace swarmbox::faults {

// Without rate_kbit, the link's ceiling assumed for the queue limit [kbit/s] (the veth under a
// Docker bridge is faster; a radio mesh is not).
inline constexpr double kAssumedLinkRateKbit = 100000.0;
// Small packets (DDS heartbeats, ACKs) dominate a swarm's mesh traffic [bytes].
inline constexpr double kAssumedPacketBytes = 128.0;
inline constexpr std::uint32_t kNetemDefaultLimit = 1000;
inline constexpr std::string_view kRadioChainOut = "SWARMBOX-RADIO-OUT";
inline constexpr std::string_view kRadioChainIn = "SWARMBOX-RADIO-IN";
inline constexpr std::size_t kMaxRadioRules = 64;

struct LinkTarget {
  std::string node;            // drone name (messages)
  std::string mesh_interface;  // e.g. "eth1": the agent's mesh link, seen from its namespace
  std::map<std::string, std::string> peer_ipv4;  // peer drone name -> its mesh IPv4 address
  double link_rate_kbit = kAssumedLinkRateKbit;
};

struct RadioPlanOptions {
  std::uint16_t first_queue = 0;   // NFQUEUE numbers first_queue .. first_queue + rules - 1
  std::uint64_t seed = 0;          // the trial's seed; each daemon gets a seed derived from it
  std::string netemd = "/usr/bin/swarmbox-netemd";  // the daemon's path in the sidecar
  std::string pid_dir = "/run";
};

struct RadioPlan {
  Mechanism mechanism = Mechanism::kKernelNetem;
  std::vector<Command> apply;  // run in order, stop at the first failure (RunCommands)
  std::vector<Command> undo;   // run all, report the first failure (RunAllCommands)
};

// Refuses (kInvalidArgument) rules the mechanism cannot honour, an unknown peer (no address), more
// than kMaxRadioRules rules, or an empty interface name. No rules gives an empty plan.
Result<RadioPlan> PlanRadio(const std::vector<RadioRule>& rules, const LinkTarget& link,
                            Mechanism mechanism, const RadioPlanOptions& options = {});

// Going from one set of rules to another on the same link: undo(old) then apply(new).
Result<RadioPlan> PlanRadioChange(const std::vector<RadioRule>& from, const std::vector<RadioRule>& to,
                                  const LinkTarget& link, Mechanism mechanism,
                                  const RadioPlanOptions& options = {});

// A radio fault over a base (the network.mesh rules): an overlay with an all-traffic rule replaces
// the base; otherwise the overlay's per-destination rules replace the base's for those peers.
std::vector<RadioRule> ComposeRadio(const std::vector<RadioRule>& base, const std::vector<RadioRule>& overlay);

// netem's queue limit for `spec` on a link of link_rate_kbit (spec.limit_packets wins when set).
std::uint32_t NetemLimitPackets(const NetemSpec& spec, double link_rate_kbit = kAssumedLinkRateKbit);
// The netem options after "netem": {"limit", "1000", "delay", "100ms", "20ms", "25%", ...}.
std::vector<std::string> NetemOptions(const NetemSpec& spec, std::uint32_t limit_packets);

}  // namespace swarmbox::faults
