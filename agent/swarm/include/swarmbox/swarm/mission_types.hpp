// The interface of the SAR mission behaviours (scout_behaviour.hpp, lifter_sequence.hpp,
// leader_planner.hpp): what the agent feeds in every mission tick and what it gets back. Plain
// values; the agent converts at its edges:
//   SetpointRequest  -> the flight stack (takeoff / position+yaw / velocity+yaw from Flocking /
//                       land / idle),
//   PayloadRequest   -> bus::WorldCommand "payload_attach" {mass_kg} or "payload_release" {},
//   proposals        -> raft NodeDriver::Propose(command),
//   events           -> stdout, one logfmt line each (LogEvent::str()),
//   mode             -> bus::DroneState::mode (the leader reads the others' modes from it).
// Frames: world ENU [m], yaw counter-clockwise from east [rad], simulated time [s].
#pragma once

#include <span>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/raft/mission_command.hpp"
#include "swarmbox/raft/mission_state.hpp"
#include "swarmbox/swarm/detection.hpp"

namespace swarmbox::swarm {

enum class Role { kScout, kLifter };
std::string_view RoleName(Role role);  // "scout", "lifter"

enum class SetpointKind {
  kIdle,      // on the ground, motors off (disarmed)
  kTakeoff,   // climb vertically to target_m.z above target_m.x/y
  kPosition,  // fly to and hold target_m with yaw_rad (flight stack position control)
  kFlock,     // Flocking::Step with goal target_m -> velocity setpoint + yaw_rad
  kLand,      // descend and touch down at target_m.x/y, then disarm
};

struct SetpointRequest {
  SetpointKind kind = SetpointKind::kIdle;
  Eigen::Vector3d target_m = Eigen::Vector3d::Zero();
  double yaw_rad = 0.0;
  double max_speed_m_s = 0.0;  // horizontal speed cap for this leg; 0 = the flight stack's default
  bool damp_swing = false;     // a slung load hangs below: enable swing damping
};

enum class PayloadAction { kNone, kAttach, kRelease };

struct PayloadRequest {
  PayloadAction action = PayloadAction::kNone;
  double mass_kg = 0.0;  // kAttach: the payload's mass from now on [kg]
};

struct MissionInput {
  double t_s = 0.0;
  const raft::MissionState* mission = nullptr;  // committed (applied) state; never null
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();    // estimated, world ENU
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();  // estimated
  double yaw_rad = 0.0;
  double battery_fraction = 1.0;  // [0, 1]
  bool battery_low = false;       // BatteryModel::IsLow(...)
  bool payload_attached = false;  // the slung load hangs on the hook (lifter)
  std::span<const GroundDetection> detections;  // newly visible detections (after the latency)
};

struct MissionOutput {
  SetpointRequest setpoint;
  PayloadRequest payload;
  std::vector<raft::MissionCommand> proposals;
  std::vector<LogEvent> events;
  std::string_view mode = "on_ground";  // static string, e.g. "searching"

  void Clear() {
    payload = {};
    proposals.clear();
    events.clear();
  }
};

}  // namespace swarmbox::swarm
