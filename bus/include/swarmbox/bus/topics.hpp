// Topic names and QoS presets of the SwarmBox bus: which message travels where.
//
// Traffic from the physics server to one drone has a topic per drone so it does not fan out to every
// drone (100 agents must not each receive 100 sensor streams). Traffic from every drone to the
// physics server shares one keyed topic (sim/actuator, keyed by ActuatorCommand::drone): the server
// reads it with one reader, so its per-step work and its endpoint count do not grow with a reader
// per drone, and no agent subscribes to it (no fan-out). Radio-wide traffic shares one topic per
// type and is addressed by drone name where needed (RaftMessage::to, RadioPing::to).
//
//   domain  topic                      type             QoS         direction
//   sim     sim/clock                  ClockTick        kLockstep   physics -> all
//   sim     sim/<drone>/sensor         SensorSample     kLockstep   physics -> agent <drone>
//   sim     sim/actuator               ActuatorCommand  kLockstep   every agent -> physics (keyed by drone)
//   sim     sim/<drone>/camera         CameraImage      kLockstep   physics -> agent <drone>
//   sim     sim/<drone>/stereo         CameraImage      kLockstep   physics -> agent <drone> (a stereo pair)
//   sim     sim/world_command          WorldCommand     kLockstep   orchestrator/tools -> physics
//   sim     sim/status                 Event            kLockstep   physics -> all (the start, 1 Hz)
//   sim     sim/telemetry              Telemetry        kState      every agent -> physics (keyed by drone; the recording)
//   sim     sim/depth                  DepthSummary     kState      every agent -> anyone (keyed by drone; stereo depth)
//   sim     sim/<drone>/depth          CameraImage      kLockstep   agent <drone> -> anyone (its depth image, 16UC1 mm)
//   mesh    mesh/state                 DroneState       kState      agent -> agents (keyed by drone)
//   mesh    mesh/raft                  RaftMessage      kRadio      agent -> agent `to`
//   mesh    mesh/detection             Detection        kRadio      agent -> agents
//   mesh    mesh/ping                  RadioPing        kRadio      agent -> agent `to` (and back)
//   mesh    mesh/brain                 BrainMessage     kRadio      brain -> brains (`to` or all)
//   sim     offboard/<drone>/input     BrainInput       kLockstep   agent <drone> -> its brain
//   sim     offboard/<drone>/output    BrainOutput      kLockstep   brain -> agent <drone>
//   both    event                      Event            kRadio      anyone -> loggers
//
// Topic names may hold only ASCII letters, digits, '_' and '/', and must start with a letter
// (Cyclone DDS rejects anything else, so the rule is checked up front for both backends). Drone
// names must therefore be [A-Za-z0-9_]+.
#pragma once

#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"

namespace swarmbox::bus {

// QoS presets. A subscriber must use the same preset as the publishers it wants to hear
// (a best-effort subscriber would also hear a reliable publisher, but not the reverse).
// All presets are volatile (no history for late joiners) and keep-last.
enum class Qos {
  // Reliable, keep-last 16 (per instance: per drone on sim/actuator). For the lossless sim
  // network: sensor/actuator lockstep, camera, clock, world commands. A dead reader never blocks
  // the writer for long: history is keep-last, old samples are overwritten.
  kLockstep,
  // Best-effort, keep-last 256. For the radio: Raft, detections, pings, events. Loss on the mesh
  // stays visible to the application (Raft and the ping protocol do their own retries).
  kRadio,
  // Reliable, keep-last 1 per instance (DroneState is keyed by drone): a subscriber sees the
  // latest state of each neighbour; a lost update is repaired only by a newer one or by the
  // reliability protocol, never queued behind stale ones.
  kState,
};

std::string_view QosName(Qos qos);  // "lockstep", "radio", "state"

inline constexpr std::string_view kClockTopic = "sim/clock";
// Every agent's ActuatorCommand; the physics server reads it with one reader and identifies the
// answer by its key, ActuatorCommand::drone.
inline constexpr std::string_view kActuatorTopic = "sim/actuator";
inline constexpr std::string_view kWorldCommandTopic = "sim/world_command";
// The physics server's start (physics_server/app/joining.hpp): Event "joining" every second while
// the first step waits, "joined" once, with fields joined, expected, missing (every name, commas).
inline constexpr std::string_view kSimStatusTopic = "sim/status";
// Every agent's Telemetry for the physics server's recording (record/), keyed by drone; nothing
// decides on it.
inline constexpr std::string_view kTelemetryTopic = "sim/telemetry";
// Every agent's stereo depth summaries (DepthSummary, keyed by drone; issue #23).
inline constexpr std::string_view kDepthTopic = "sim/depth";
inline constexpr std::string_view kDroneStateTopic = "mesh/state";
inline constexpr std::string_view kRaftTopic = "mesh/raft";
inline constexpr std::string_view kDetectionTopic = "mesh/detection";
inline constexpr std::string_view kRadioPingTopic = "mesh/ping";
inline constexpr std::string_view kBrainMessageTopic = "mesh/brain";
inline constexpr std::string_view kEventTopic = "event";

std::string SensorTopic(std::string_view drone);    // "sim/<drone>/sensor"
std::string CameraTopic(std::string_view drone);    // "sim/<drone>/camera"
// A stereo airframe's rectified pair, one CameraImage per pair, left and right side by side
// (the layout is CameraImage's comment in messages.hpp); issue #23.
std::string StereoTopic(std::string_view drone);    // "sim/<drone>/stereo"
// A stereo drone's depth images (issue #23), as its depth camera releases them: one CameraImage per
// matched pair, published by the drone's agent at the same simulated time as the frame's
// DepthSummary on kDepthTopic (the device's 30-50 ms after the exposure), Qos::kLockstep.
//   encoding "16UC1": depth along the optical axis (Z, not range) in millimetres, little-endian
//   uint16, 0 = no depth (ROS's REP 118 convention; what the OAK-D Pro itself puts out). Chosen over
//   "32FC1" metres because it is half the bytes (640x400: 512,000 bytes a frame against 1,024,000)
//   for 1 mm steps, far finer than SGBM's depth step (a 1/16 px disparity step is 0.19 m at 10 m);
//   depth over 65.535 m (a disparity under 0.5 px at the OAK-D Pro's 640x400) is sent as 0.
//   width_px, height_px: the left image's; row_stride_bytes = 2 * width_px;
//   intrinsics, camera_pose: the LEFT camera's (rectified: distortion 0; the pose the drone's own
//   estimate gave at the exposure), so a subscriber back-projects pixel (u, v) with depth Z to
//   camera_pose * (Z (u - cx) / fx, Z (v - cy) / fy, Z);
//   sim_time_ns, step: the exposure's (the pair's), as the summary's capture time.
// Published only while a subscriber is matched: a drone nobody listens to pays nothing for it.
std::string DepthImageTopic(std::string_view drone);  // "sim/<drone>/depth"
std::string OffboardInputTopic(std::string_view drone);   // "offboard/<drone>/input"
std::string OffboardOutputTopic(std::string_view drone);  // "offboard/<drone>/output"

// kInvalidArgument with the offending character and the rule when `topic` is not a valid name.
Status ValidateTopicName(std::string_view topic);

// kInvalidArgument unless `drone` is a non-empty [A-Za-z0-9_]+ name.
Status ValidateDroneName(std::string_view drone);

}  // namespace swarmbox::bus
