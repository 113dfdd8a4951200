// Fault records for events.jsonl: one JSON object per line when a fault is requested, applied,
// asked to end, removed, or fails, saying which mechanism carried it out (ARCHITECTURE.md
// "Faults": the injector records which one it used).
//
//   {"type":"fault","phase":"requested","fault":"fault_2","kind":"radio","start":"at 30s",
//    "t_sim_s":30.012,"wall_s":31.4,"targets":["scout_1"],"mechanism":"userspace-nfqueue",
//    "spec":"delay_ms=100 jitter_ms=20 distribution=normal loss=0.05"}
//   {"type":"fault","phase":"applied",...,"t_sim_s":31.9,"wall_s":33.1,...,
//    "requested_t_sim_s":30.012,"requested_wall_s":31.4}
//
// Phases: "requested" when the timeline asks for the fault (before anything is done), "applied"
// once the mechanism confirmed it on every target (fault_injector.hpp says what confirms it),
// "remove_requested" and "removed" the same for its end, "failed" instead of "applied"/"removed".
// t_sim_s/wall_s are when the record's phase happened; applied/removed also carry the request's
// times (requested_t_sim_s, requested_wall_s).
// "error" is added for phase "failed"; "note" when the record says how something was done, e.g. a
// removal at the end of the trial left to the sidecar's removal (the rules die with its network
// namespace; fault_injector.hpp). Mechanisms: "netem", "userspace-nfqueue" (radio), "iptables"
// (partition), "docker" (kill/stop/pause/restart), "physics-command" (sensor and environment faults).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/faults/fault_spec.hpp"

namespace swarmbox::faults {

enum class FaultPhase { kRequested, kApplied, kRemoveRequested, kRemoved, kFailed };
std::string_view FaultPhaseName(FaultPhase phase);

// "delay_ms=100 jitter_ms=20 ..." for a rule, "to=[a, b]" last; "" for an empty spec.
std::string DescribeRule(const RadioRule& rule);
// The kind's parameters in one line, e.g. "groups=[[a, b], [c]] oneway=false", "signal=SIGKILL".
std::string DescribeFault(const Fault& fault);

struct FaultEventRecord {
  FaultPhase phase = FaultPhase::kApplied;
  double t_sim_s = 0.0;  // simulated time when it happened
  double wall_s = 0.0;   // wall seconds since the trial's Run
  std::vector<std::string> targets;
  std::string mechanism;
  std::string error;     // kFailed only
  std::string note;      // optional, any phase: how it was done when that is not the mechanism's
                         // usual way (e.g. "with the sidecar's network namespace")
  // kApplied/kRemoved: when it was requested (written as requested_t_sim_s, requested_wall_s).
  std::optional<double> requested_t_sim_s;
  std::optional<double> requested_wall_s;
};

// One line of events.jsonl (no trailing newline).
std::string FaultEventJson(const Fault& fault, const FaultEventRecord& record);

// The network.mesh impairment on one agent, applied at Run or removed at shutdown:
//   {"type":"mesh","phase":"applied","node":"scout_1","t_sim_s":0,"wall_s":0.8,
//    "mechanism":"userspace-nfqueue","spec":"delay_ms=100 jitter_ms=20 loss=0.05"}
std::string MeshEventJson(const std::string& node, const std::vector<RadioRule>& rules,
                          const FaultEventRecord& record);

}  // namespace swarmbox::faults
