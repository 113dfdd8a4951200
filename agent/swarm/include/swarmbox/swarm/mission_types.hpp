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

#include <optional>
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

// The host's answer to MissionOutput::want_drop_spot (the lifter's survey of its drop point): what
// agent/depth's ChooseDropSpot found in a depth frame. Plain values, so that agent/swarm needs no
// OpenCV.
struct DropSpotAnswer {
  bool found = false;                                // a flat, clear footprint at xy_m
  Eigen::Vector2d xy_m = Eigen::Vector2d::Zero();    // its centre, world ENU [m]
  double slope_deg = 0;                              // the ground's slope there [deg]
  double height_m = 0;                               // the ground's height there, world [m]
  bool default_ok = false;                           // the default point itself passed
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
  // The lifter's drop-spot survey: the answer to an earlier want_drop_spot, once (the host sets it
  // on one step and clears it after).
  std::optional<DropSpotAnswer> drop_spot;
  // The scout's safe height (ScoutConfig::min_clearance_m): the highest surface under and around
  // the drone from its depth camera (agent/depth ClearanceBelow's top_z_m), world z [m], from a
  // fresh frame (the host sets it on the step a frame arrives); absent: no depth this step (none
  // within the camera's 15 m range, no camera, or no new frame).
  std::optional<double> obstacle_top_z_m;
};

struct MissionOutput {
  SetpointRequest setpoint;
  PayloadRequest payload;
  std::vector<raft::MissionCommand> proposals;
  std::vector<LogEvent> events;
  std::string_view mode = "on_ground";  // static string, e.g. "searching"
  // The lifter asks for a drop spot (every step until answered or timed out): choose a footprint
  // near drop_spot_default_xy_m with the stretcher's length along drop_spot_yaw_rad, from a depth
  // frame taken now, and answer in MissionInput::drop_spot.
  bool want_drop_spot = false;
  Eigen::Vector2d drop_spot_default_xy_m = Eigen::Vector2d::Zero();  // world ENU [m]
  double drop_spot_yaw_rad = 0;                                       // from east, CCW [rad]
  Eigen::Vector2d drop_spot_victim_xy_m = Eigen::Vector2d::Zero();   // the spot stays off the victim

  void Clear() {
    payload = {};
    want_drop_spot = false;
    drop_spot_default_xy_m = Eigen::Vector2d::Zero();
    drop_spot_yaw_rad = 0;
    drop_spot_victim_xy_m = Eigen::Vector2d::Zero();
    proposals.clear();
    events.clear();
  }
};

}  // namespace swarmbox::swarm
