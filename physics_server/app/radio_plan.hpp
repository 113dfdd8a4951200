// RadioPlan: the simulated-time faults of a trial, written by the orchestrator as JSON and read by
// swarmbox-physics `--radio-plan PATH` (the contract: design of issue #17, "Radio plan JSON").
// Pure: parsing and checks only; SimServer carries the entries out at their simulated times.
//
//   {"seed": 42,
//    "mesh": {"delay_ms": 100, "jitter_ms": 20, "distribution": "normal", "loss": 0.05},
//    "schedule": [
//      {"at_s": 30.0, "name": "kill_leader", "kind": "drone_out", "mode": "kill",
//       "targets": ["raft_leader"], "duration_s": 0},
//      {"at_s": 20.0, "name": "deg", "kind": "radio", "targets": ["scout_1"],
//       "impairment": {"delay_ms": 300, "loss": 0.2}, "duration_s": 10},
//      {"at_s": 40.0, "name": "split", "kind": "partition",
//       "groups": [["scout_1"], ["scout_2", "lifter"]], "oneway": false, "duration_s": 20},
//      {"at_s": 5.0, "name": "gps", "kind": "world_command", "target": "scout_1",
//       "command": "gps_dropout", "args": [10.0]}]}
//
// Kinds:
//   drone_out      targets (drone names or "raft_leader") leave the lockstep at at_s: mode kill
//                  (stays out; duration_s must be 0), stop / pause / restart (back after
//                  duration_s > 0, as a joining drone; restart: as a new agent process).
//   world_command  one world command (world_commands.hpp) at at_s; target "" = the whole world.
//   radio          an egress impairment of each target (a drone name; radio.model channel only)
//                  from at_s for duration_s (0 = to the end).
//   partition      no frame crosses between the groups (oneway: only from the first group to the
//                  others) from at_s for duration_s (0 = to the end; channel only).
// Errors are kInvalidArgument at `file:line:col` of the offending node (yaml.hpp marks).
// Times: at_s and duration_s are simulated seconds >= 0, kept as whole nanoseconds.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "swarmbox/channel/channel.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::physics {

// netem-like egress impairment of a sender (the trial's network.mesh keys): the channel's own
// struct. Units in the names; loss and duplicate are probabilities in [0, 1]; the plan accepts
// every netem distribution (normal|uniform|pareto|paretonormal), the channel fewer
// (CheckChannelPlan).
using PlanImpairment = channel::Impairment;

// The target that names the drone leading the Raft group at the entry's time.
inline constexpr const char* kRaftLeaderTarget = "raft_leader";

struct PlanEntry {
  enum class Kind { kDroneOut, kWorldCommand, kRadio, kPartition };
  enum class Mode { kKill, kStop, kPause, kRestart };
  std::int64_t at_ns = 0;
  std::int64_t duration_ns = 0;       // 0: no end (kill, or a radio fault to the end)
  std::string name;
  Kind kind = Kind::kDroneOut;
  std::vector<std::string> targets;   // drone_out, radio
  Mode mode = Mode::kKill;            // drone_out
  PlanImpairment impairment;          // radio
  std::vector<std::vector<std::string>> groups;  // partition
  bool oneway = false;                // partition
  std::string target;                 // world_command ("" = the whole world)
  std::string command;                // world_command
  std::vector<double> args;           // world_command
  std::string where;                  // "plan.json:3:5", for messages
};

struct RadioPlan {
  std::optional<std::uint64_t> seed;  // the channel's seed (the trial's); absent: --seed
  std::optional<PlanImpairment> mesh;  // absent: no impairment
  std::vector<PlanEntry> schedule;     // sorted by at_ns, file order among equal times
};

const char* ModeName(PlanEntry::Mode mode);     // "kill", "stop", "pause", "restart"
const char* KindName(PlanEntry::Kind kind);     // "drone_out", "world_command", "radio", "partition"

Result<RadioPlan> ParseRadioPlan(const yaml::Node& root);
Result<RadioPlan> LoadRadioPlan(const std::string& path);

// Every drone the plan names exists in `drones` (raft_leader aside), and world commands pass the
// world-command table: the first problem, at its entry.
Status CheckRadioPlan(const RadioPlan& plan, const std::vector<std::string>& drones);

}  // namespace swarmbox::physics
