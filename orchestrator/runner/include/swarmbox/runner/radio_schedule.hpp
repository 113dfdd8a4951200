// The radio plan: what the physics server carries out in simulated time for a `radio.model:
// channel` trial (the file it reads with --radio-plan; ARCHITECTURE.md "Faults", the radio plan). Pure: a
// TrialSpec in, a plan and its JSON out; the runner writes it into the trial folder and copies it
// into the physics container (plan.hpp kRadioPlanPath).
//
//   auto plan = PlanRadioSchedule(spec);          // kInvalidArgument with the reason and where
//   std::string json = RadioScheduleJson(*plan);
//
//   {"seed": 42,
//    "mesh": {"delay_ms": 100, "jitter_ms": 20, "distribution": "normal", "loss": 0.05,
//             "rate_kbit": 0, "duplicate": 0},
//    "schedule": [
//      {"at_s": 5, "name": "gps", "kind": "world_command", "target": "scout_1",
//       "command": "gps_dropout", "args": [10]},
//      {"at_s": 30, "name": "kill_leader", "kind": "drone_out", "mode": "kill",
//       "targets": ["raft_leader"], "duration_s": 0},
//      ...]}
//
// What goes in:
//   - `mesh`: network.mesh, the impairment of every sender's egress (absent: none);
//   - `schedule`: every fault whose trigger is a simulated time (`at:`), sorted by (at_s, the
//     fault's place in `faults:`):
//       kill/stop/pause/restart  `drone_out` in the physics server's modes: kill without a
//                                duration: mode kill, duration_s 0 (stays out); kill with one: mode
//                                restart for its duration (out, then back as a new process); stop
//                                and pause: their mode and duration (none: faults::kUntilEndS, the
//                                rest of the trial); restart: out for one lockstep step (0.004 s).
//                                The runner carries out the fault's own container action (kill with
//                                its signal, stop, pause) when the server reports the drone out,
//                                and the reverse when it reports it back (fault_injector.hpp);
//       radio                    `radio`, the fault's one all-traffic rule as `impairment`;
//       partition                `partition`, groups as written plus the drones in no group as one
//                                more group, `oneway`;
//       gps_dropout, gps_degrade, imu_bias, wind_gust
//                                `world_command` per target, the calls faults::PlanPhysicsFault
//                                makes (their duration in their args; an imu_bias with a duration
//                                gets its negated jump as a second entry at at + duration);
//                                target "" = the whole world (wind_gust).
//   Targets are resolved here (names, globs, `all`; `random` draws from a std::mt19937_64 seeded
//   with the trial's seed, in schedule order, as the fault injector's ResolveTarget does) except
//   `raft_leader`, which the physics server resolves when the entry is due.
// Faults triggered by a log event (`on:`) or a wall time (`at_wall:`) stay with the runner's fault
// injector (process and world faults; the loader refuses radio faults and partitions so triggered
// in channel mode). With `radio.model: netem` there is no plan: the runner carries out every fault
// as before (fault_injector.hpp).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/dsl/trial_spec.hpp"
#include "swarmbox/faults/fault_spec.hpp"
#include "swarmbox/faults/netem_spec.hpp"

namespace swarmbox::runner {

struct ScheduleEntry {
  enum class Kind { kDroneOut, kRadio, kPartition, kWorldCommand };
  Kind kind = Kind::kDroneOut;
  double at_s = 0.0;                 // simulated time [s]
  std::string name;                  // the fault's id (`name:` or fault_<index>)
  double duration_s = 0.0;           // drone_out, radio, partition; 0 = until the end
  std::vector<std::string> targets;  // drone_out, radio: drone names or "raft_leader"
  faults::ProcessAction mode = faults::ProcessAction::kKill;  // drone_out
  faults::NetemSpec impairment;                               // radio
  std::vector<std::vector<std::string>> groups;               // partition
  bool oneway = false;                                        // partition
  std::string target;        // world_command: a drone, "raft_leader", "" = world
  std::string command;       // world_command
  std::vector<double> args;  // world_command
};

struct RadioSchedule {
  std::uint64_t seed = 0;
  std::optional<faults::NetemSpec> mesh;
  std::vector<ScheduleEntry> schedule;
};

// Whether the fault goes into the radio plan (its trigger is a simulated time) in a channel trial.
bool InRadioSchedule(const faults::Fault& fault);

// kInvalidArgument for a netem trial (it has no plan) or what the channel does not carry out
// (faults::CheckChannelSupports / CheckChannelFaults, as the loader refuses it), kNotFound for a
// target that matches no drone.
Result<RadioSchedule> PlanRadioSchedule(const dsl::TrialSpec& spec);

// The file the physics server reads (one line, no trailing newline).
std::string RadioScheduleJson(const RadioSchedule& plan);

}  // namespace swarmbox::runner
