// Fault schedule: the `faults:` list of a trial file (and the C++ DSL's view of it).
//
// Each entry has a start, an optional duration (the fault is undone when it ends), a target and
// exactly one kind:
//
//   faults:
//     - {at: 30s, kill: raft_leader}                              # simulated time
//     - {at_wall: 10s, duration: 20s, pause: [scout_1, scout_2]}  # wall time since Run
//     - {on: "event=leader_elected", stop: {target: random, timeout: 5s}, duration: 15s}
//     - {at: 40s, duration: 30s, radio: {target: "scout_*", delay_ms: 200, jitter_ms: 50,
//                                        distribution: normal, loss: 0.1}}
//     - {at: 60s, duration: 30s, partition: {groups: [[scout_1, scout_2], [lifter]], oneway: false}}
//     - {at: 20s, duration: 10s, gps_dropout: scout_2}
//     - {at: 30s, duration: 20s, gps_degrade: {target: scout_1, h_acc_m: 5, v_acc_m: 8}}
//     - {at: 25s, duration: 10s, imu_bias: {target: lifter, accel_m_s2: [0.2, 0, 0]}}
//     - {at: 50s, duration: 5s, wind_gust: {speed_m_s: 12, direction_deg: 270}}
//
// Targets: a drone name, a list of names, a glob pattern ("scout_*"), `all`, `raft_leader` (the
// leader of the latest `event=leader_elected` seen in the logs when the fault fires) or `random`
// (one drone, drawn from the trial's seed). Kinds kill/stop/pause/restart/gps_dropout take the
// target as their value or as `target:` in a mapping; radio, imu_bias and gps_degrade as `target:`
// (radio defaults to all). Partitions name their groups; drones listed in no group form one more group.
// wind_gust acts on the world and has no target.
//
// ParseFaults() checks shape and values (file:line:col); ValidateFaults() checks names against the
// trial's drones. Both return kInvalidArgument with the reason.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/faults/netem_spec.hpp"

namespace swarmbox::faults {

struct FaultStart {
  enum class Clock { kSim, kWall, kEvent };
  Clock clock = Clock::kSim;
  std::int64_t at_ms = 0;     // kSim: simulated time; kWall: wall time since the trial's Run
  std::string event_pattern;  // kEvent: a log pattern such as "event=leader_elected"
  std::string ToString() const;  // "at 30s", "at_wall 10s", "on event=leader_elected"
};

struct FaultTarget {
  enum class Kind { kAll, kNames, kPattern, kRaftLeader, kRandom };
  Kind kind = Kind::kAll;
  std::vector<std::string> names;  // kNames
  std::string pattern;             // kPattern: fnmatch glob
  std::string ToString() const;    // "all", "scout_1", "[a, b]", "scout_*", "raft_leader", "random"
};

struct RadioFault {
  FaultTarget target;
  std::vector<RadioRule> rules;  // at least one
};

struct PartitionFault {
  std::vector<std::vector<std::string>> groups;  // as written; the implicit rest is added on plan
  bool oneway = false;  // true: traffic from groups[0] to the others is cut, the reverse flows
};

enum class ProcessAction { kKill, kStop, kPause, kRestart };
std::string_view ProcessActionName(ProcessAction action);

struct ProcessFault {
  ProcessAction action = ProcessAction::kKill;
  FaultTarget target;
  std::string signal = "SIGKILL";  // kill only
  int timeout_s = 10;              // stop/restart: SIGTERM, then SIGKILL after this
};

// Sensor and environment faults: data for the physics server (it applies them).
struct GpsDropout {
  FaultTarget target;
};
// Worse GPS fixes: the 1-sigma noise of each fix becomes h_acc_m / v_acc_m (the receiver reports
// them as its accuracy) for the fault's duration, then the airframe's own accuracy is back.
struct GpsDegrade {
  FaultTarget target;
  double h_acc_m = 0.0;  // horizontal 1-sigma [m], (0, kMaxGpsAccuracyM]
  double v_acc_m = 0.0;  // vertical 1-sigma [m], (0, kMaxGpsAccuracyM]
};
// The worst accuracy a gps_degrade may ask for [m] (beyond it, ask for a gps_dropout).
inline constexpr double kMaxGpsAccuracyM = 1000.0;
struct ImuBias {
  FaultTarget target;
  std::array<double, 3> accel_m_s2{};  // added to the accelerometer [m/s^2], body frame FRD
  std::array<double, 3> gyro_rad_s{};  // added to the gyroscope [rad/s], body frame FRD
};
struct WindGust {
  double speed_m_s = 0.0;      // horizontal gust speed [m/s]
  double direction_deg = 0.0;  // direction the wind blows FROM, degrees clockwise from north
  double vertical_m_s = 0.0;   // up positive [m/s]
};

using FaultAction =
    std::variant<RadioFault, PartitionFault, ProcessFault, GpsDropout, GpsDegrade, ImuBias, WindGust>;

struct Fault {
  std::string id;  // `name:` when given, else "fault_<index>"
  FaultStart start;
  std::optional<std::int64_t> duration_ms;  // absent: never undone
  FaultAction action;
  yaml::Mark mark;
  // "radio", "partition", "kill", "stop", "pause", "restart", "gps_dropout", "gps_degrade",
  // "imu_bias", "wind_gust".
  std::string_view kind() const;
  // The target when the kind has one (partitions and wind gusts have none).
  const FaultTarget* target() const;
};

// The `faults:` node: a list of mappings (null/absent = no faults).
Result<std::vector<Fault>> ParseFaults(const yaml::Node& list);
Result<FaultTarget> ParseTarget(const yaml::Node& node);
// Names, patterns, partition groups and per-destination peers against the trial's drones.
Status ValidateFaults(const std::vector<Fault>& faults, const std::vector<std::string>& drones);

}  // namespace swarmbox::faults
