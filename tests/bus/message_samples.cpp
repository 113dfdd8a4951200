#include "message_samples.hpp"

#include <string>

namespace swarmbox::bus::testing {
namespace {

// Distinct, exactly representable doubles: seed-dependent and different per call site `k`.
double D(std::uint64_t seed, int k) { return static_cast<double>(seed) * 1000.0 + k + 0.25; }
std::string S(std::uint64_t seed, const char* what) {
  return std::string(what) + "_" + std::to_string(seed) + "_padded_beyond_sso";
}

}  // namespace

ClockTick FullClockTick(std::uint64_t seed) {
  ClockTick m;
  m.step = seed + 1;
  m.sim_time_ns = static_cast<std::int64_t>(seed) * 4'000'000 + 7;
  m.step_period_ns = 4'000'000;
  m.rtf = 0.5 + static_cast<double>(seed);
  return m;
}

SensorSample FullSensorSample(std::uint64_t seed) {
  SensorSample m;
  m.drone = "drone_" + std::to_string(seed);
  m.step = seed + 11;
  m.sim_time_ns = static_cast<std::int64_t>(seed) + 12;
  m.imu.valid = true;
  m.imu.accel_m_s2 = {D(seed, 1), D(seed, 2), D(seed, 3)};
  m.imu.gyro_rad_s = {D(seed, 4), D(seed, 5), D(seed, 6)};
  m.imu.temperature_c = D(seed, 7);
  m.baro.valid = true;
  m.baro.pressure_pa = D(seed, 8);
  m.baro.altitude_m = D(seed, 9);
  m.baro.temperature_c = D(seed, 10);
  m.mag.valid = true;
  m.mag.field_gauss = {D(seed, 11), D(seed, 12), D(seed, 13)};
  m.gps.valid = true;
  m.gps.fix_type = GpsFix::k3d;
  m.gps.num_satellites = static_cast<std::uint8_t>(9 + seed % 7);
  m.gps.latitude_deg = D(seed, 14);
  m.gps.longitude_deg = D(seed, 15);
  m.gps.altitude_m = D(seed, 16);
  m.gps.position_enu_m = {D(seed, 17), D(seed, 18), D(seed, 19)};
  m.gps.velocity_enu_m_s = {D(seed, 20), D(seed, 21), D(seed, 22)};
  m.gps.h_acc_m = D(seed, 23);
  m.gps.v_acc_m = D(seed, 24);
  m.battery.valid = true;
  m.battery.voltage_v = D(seed, 25);
  m.battery.current_a = D(seed, 26);
  m.battery.remaining = D(seed, 27);
  m.camera_frame = true;
  m.stereo_frame = true;
  m.radio_in = {FullRadioFrame(seed, 0), FullRadioFrame(seed + 1, 1), FullRadioFrame(seed + 2, 2),
                FullRadioFrame(seed + 3, 3), FullRadioFrame(seed + 4, 4)};
  return m;
}

ActuatorCommand FullActuatorCommand(std::uint64_t seed) {
  ActuatorCommand m;
  m.drone = "drone_" + std::to_string(seed);
  m.step = seed + 21;
  m.sim_time_ns = static_cast<std::int64_t>(seed) + 22;
  m.armed = true;
  m.motor_throttle = {D(seed, 1), D(seed, 2), D(seed, 3), D(seed, 4), D(seed, 5), D(seed, 6)};
  m.raft_leader = true;
  m.world = {FullWorldCommand(seed), FullWorldCommand(seed + 1)};
  m.radio_out = {FullRadioFrame(seed, 2), FullRadioFrame(seed + 5, 0)};
  return m;
}

CameraImage FullCameraImage(std::uint64_t seed, std::uint32_t width_px, std::uint32_t height_px) {
  CameraImage m;
  m.drone = "drone_" + std::to_string(seed);
  m.step = seed + 31;
  m.sim_time_ns = static_cast<std::int64_t>(seed) + 32;
  m.width_px = width_px;
  m.height_px = height_px;
  m.row_stride_bytes = width_px;
  m.encoding = "mono8";
  m.intrinsics.fx_px = D(seed, 1);
  m.intrinsics.fy_px = D(seed, 2);
  m.intrinsics.cx_px = D(seed, 3);
  m.intrinsics.cy_px = D(seed, 4);
  m.intrinsics.distortion = {D(seed, 5), D(seed, 6), D(seed, 7), D(seed, 8), D(seed, 9)};
  m.camera_pose.position_enu_m = {D(seed, 10), D(seed, 11), D(seed, 12)};
  m.camera_pose.orientation_wxyz = {D(seed, 13), D(seed, 14), D(seed, 15), D(seed, 16)};
  m.data.resize(static_cast<std::size_t>(width_px) * height_px);
  for (std::size_t i = 0; i < m.data.size(); ++i) {
    m.data[i] = static_cast<std::uint8_t>((i * 31 + seed) & 0xff);
  }
  return m;
}

WorldCommand FullWorldCommand(std::uint64_t seed) {
  WorldCommand m;
  m.seq = seed + 41;
  m.sim_time_ns = static_cast<std::int64_t>(seed) + 42;
  m.target = "drone_" + std::to_string(seed);
  m.command = "wind_gust";
  m.args = {D(seed, 1), D(seed, 2), D(seed, 3), D(seed, 4)};
  return m;
}

DroneState FullDroneState(std::uint64_t seed) {
  DroneState m;
  m.drone = "drone_" + std::to_string(seed);
  m.seq = seed + 51;
  m.sim_time_ns = static_cast<std::int64_t>(seed) + 52;
  m.wall_time_ns = static_cast<std::int64_t>(seed) + 1'700'000'000'000'000'000;
  m.position_enu_m = {D(seed, 1), D(seed, 2), D(seed, 3)};
  m.velocity_enu_m_s = {D(seed, 4), D(seed, 5), D(seed, 6)};
  m.heading_rad = D(seed, 7);
  m.battery_fraction = D(seed, 8);
  m.mode = S(seed, "search");
  return m;
}

RaftMessage FullRaftMessage(std::uint64_t seed, std::size_t payload_bytes) {
  RaftMessage m;
  m.from = S(seed, "from");
  m.to = S(seed, "to");
  m.term = seed + 61;
  m.payload.resize(payload_bytes);
  for (std::size_t i = 0; i < payload_bytes; ++i) {
    m.payload[i] = static_cast<std::uint8_t>((i * 7 + seed + 1) & 0xff);
  }
  return m;
}

Detection FullDetection(std::uint64_t seed) {
  Detection m;
  m.from = S(seed, "from");
  m.seq = seed + 71;
  m.sim_time_ns = static_cast<std::int64_t>(seed) + 72;
  m.label = S(seed, "victim");
  m.confidence = D(seed, 1);
  m.position_enu_m = {D(seed, 2), D(seed, 3), D(seed, 4)};
  m.position_sigma_m = D(seed, 5);
  return m;
}

RadioPing FullRadioPing(std::uint64_t seed) {
  RadioPing m;
  m.from = S(seed, "from");
  m.to = S(seed, "to");
  m.seq = seed + 81;
  m.sent_ns = static_cast<std::int64_t>(seed) + 82;
  m.is_pong = true;
  return m;
}

BrainMessage FullBrainMessage(std::uint64_t seed) {
  BrainMessage m;
  m.from = S(seed, "from");
  m.to = S(seed, "to");
  m.topic = S(seed, "rendezvous/vote");
  m.payload = {static_cast<std::uint8_t>(seed & 0xff), 0, 255, 17, 42};
  return m;
}

RadioFrame FullRadioFrame(std::uint64_t seed, int which) {
  RadioFrame m;
  m.from = S(seed, "from");
  m.to = which == 1 ? std::string() : S(seed, "to");  // "" = broadcast
  m.seq = seed + 85;
  m.sent_ns = static_cast<std::int64_t>(seed) + 86;
  m.delivered_ns = static_cast<std::int64_t>(seed) + 87;
  m.size_bytes = static_cast<std::uint32_t>(seed + 88);
  switch (which) {
    case 0: m.state_msg = {FullDroneState(seed)}; break;
    case 1: m.detection_msg = {FullDetection(seed)}; break;
    case 2: m.raft_msg = {FullRaftMessage(seed, 40)}; break;
    case 3: m.ping_msg = {FullRadioPing(seed)}; break;
    default: m.brain_msg = {FullBrainMessage(seed)}; break;
  }
  return m;
}

Event FullEvent(std::uint64_t seed) {
  Event m;
  m.node = S(seed, "node");
  m.sim_time_ns = static_cast<std::int64_t>(seed) + 92;
  m.name = S(seed, "leader_elected");
  m.fields = {{"term", std::to_string(seed)}, {S(seed, "leader_key"), S(seed, "leader_value")},
              {"empty_value", ""}};
  return m;
}

BrainInput FullBrainInput(std::uint64_t seed) {
  BrainInput m;
  m.drone = S(seed, "drone");
  m.sim_time_ns = static_cast<std::int64_t>(seed) + 101;
  VehicleState& v = m.vehicle;
  v.drone = m.drone;
  v.step = seed + 102;
  v.sim_time_ns = m.sim_time_ns;
  v.position_enu_m = {D(seed, 11), D(seed, 12), D(seed, 13)};
  v.velocity_enu_m_s = {D(seed, 14), D(seed, 15), D(seed, 16)};
  v.attitude_wxyz = {D(seed, 17), D(seed, 18), D(seed, 19), D(seed, 20)};
  v.angular_rate_flu_rad_s = {D(seed, 21), D(seed, 22), D(seed, 23)};
  v.battery_fraction = D(seed, 24);
  v.battery_voltage_v = D(seed, 25);
  v.flight_mode = S(seed, "trajectory");
  v.armed = true;
  v.landed = false;
  v.payload_mass_kg = D(seed, 26);
  v.mass_estimate_kg = D(seed, 27);
  m.flight_events = {FullEvent(seed), FullEvent(seed + 1)};
  m.is_leader = true;
  m.leader = S(seed, "leader");
  m.neighbours = {FullDroneState(seed), FullDroneState(seed + 1)};
  m.messages = {FullBrainMessage(seed), FullBrainMessage(seed + 2)};
  m.committed = {{seed + 103, {1, 2, 3}}, {seed + 104, {}}};
  m.detections = {FullDetection(seed)};
  return m;
}

BrainOutput FullBrainOutput(std::uint64_t seed) {
  BrainOutput m;
  m.drone = S(seed, "drone");
  m.sim_time_ns = static_cast<std::int64_t>(seed) + 111;
  TrajectorySetpoint sp;
  sp.position_enu_m = {D(seed, 31), D(seed, 32), D(seed, 33)};
  sp.velocity_enu_m_s = {D(seed, 34), D(seed, 35), D(seed, 36)};
  sp.acceleration_enu_m_s2 = {D(seed, 37), D(seed, 38), D(seed, 39)};
  sp.yaw_rad = D(seed, 40);
  sp.yawspeed_rad_s = D(seed, 41);
  m.setpoint = {sp};
  m.commands = {{S(seed, "takeoff"), D(seed, 42)}, {S(seed, "payload_attach"), D(seed, 43)}};
  m.messages = {FullBrainMessage(seed + 3)};
  m.proposals = {{{9, 8, 7, 6}}, {{}}};
  m.status = S(seed, "rendezvous/flying");
  m.events = {FullEvent(seed + 4)};
  return m;
}

Telemetry FullTelemetry(std::uint64_t seed) {
  Telemetry m;
  m.drone = S(seed, "drone");
  m.sim_time_ns = static_cast<std::int64_t>(seed) + 222;
  m.position_enu_m = {D(seed, 51), D(seed, 52), D(seed, 53)};
  m.velocity_enu_m_s = {D(seed, 54), D(seed, 55), D(seed, 56)};
  m.attitude_wxyz = {D(seed, 57), D(seed, 58), D(seed, 59), D(seed, 60)};
  m.flight_mode = S(seed, "trajectory");
  m.setpoint_position_enu_m = {D(seed, 61), D(seed, 62), D(seed, 63)};
  m.setpoint_velocity_enu_m_s = {D(seed, 64), D(seed, 65), D(seed, 66)};
  m.setpoint_yaw_rad = D(seed, 67);
  m.flock_separation = {D(seed, 68), D(seed, 69), D(seed, 70)};
  m.flock_alignment = {D(seed, 71), D(seed, 72), D(seed, 73)};
  m.flock_cohesion = {D(seed, 74), D(seed, 75), D(seed, 76)};
  m.flock_sum = {D(seed, 77), D(seed, 78), D(seed, 79)};
  m.raft_role = S(seed, "leader");
  m.raft_term = seed + 5;
  m.raft_leader = S(seed, "leader_name");
  m.raft_commit_index = seed + 17;
  m.battery_fraction = D(seed, 80);
  m.mission_stage = S(seed, "scout/searching");
  m.armed = true;
  m.landed = false;
  m.links = {{S(seed, "peer_a"), D(seed, 81), D(seed, 82)}, {S(seed, "peer_b"), D(seed, 83), D(seed, 84)}};
  m.sectors = {{S(seed, "sector_drone"), {D(seed, 85), D(seed, 86), D(seed, 87), D(seed, 88)}}, {S(seed, "empty"), {}}};
  m.detections = {FullDetection(seed + 5), FullDetection(seed + 6)};
  m.events = {FullEvent(seed + 7), FullEvent(seed + 8)};
  return m;
}

DepthSummary FullDepthSummary(std::uint64_t seed) {
  DepthSummary m;
  m.drone = S(seed, "drone");
  m.capture_ns = static_cast<std::int64_t>(seed) + 333;
  m.sim_time_ns = static_cast<std::int64_t>(seed) + 444;
  m.fill_rate = D(seed, 91);
  m.median_m = D(seed, 92);
  m.near_p5_m = D(seed, 93);
  m.grid_cols = 2;
  m.grid_rows = 1;
  m.grid_m = {D(seed, 94), D(seed, 95)};
  m.camera_pose.position_enu_m = {D(seed, 96), D(seed, 97), D(seed, 98)};
  m.camera_pose.orientation_wxyz = {D(seed, 99), D(seed, 100), D(seed, 101), D(seed, 102)};
  return m;
}

template <> ClockTick Full<ClockTick>(std::uint64_t seed) { return FullClockTick(seed); }
template <> SensorSample Full<SensorSample>(std::uint64_t seed) { return FullSensorSample(seed); }
template <> ActuatorCommand Full<ActuatorCommand>(std::uint64_t seed) {
  return FullActuatorCommand(seed);
}
template <> CameraImage Full<CameraImage>(std::uint64_t seed) { return FullCameraImage(seed); }
template <> WorldCommand Full<WorldCommand>(std::uint64_t seed) { return FullWorldCommand(seed); }
template <> DroneState Full<DroneState>(std::uint64_t seed) { return FullDroneState(seed); }
template <> RaftMessage Full<RaftMessage>(std::uint64_t seed) { return FullRaftMessage(seed); }
template <> Detection Full<Detection>(std::uint64_t seed) { return FullDetection(seed); }
template <> RadioPing Full<RadioPing>(std::uint64_t seed) { return FullRadioPing(seed); }
template <> BrainMessage Full<BrainMessage>(std::uint64_t seed) { return FullBrainMessage(seed); }
template <> Event Full<Event>(std::uint64_t seed) { return FullEvent(seed); }
template <> BrainInput Full<BrainInput>(std::uint64_t seed) { return FullBrainInput(seed); }
template <> BrainOutput Full<BrainOutput>(std::uint64_t seed) { return FullBrainOutput(seed); }
template <> Telemetry Full<Telemetry>(std::uint64_t seed) { return FullTelemetry(seed); }
template <> DepthSummary Full<DepthSummary>(std::uint64_t seed) { return FullDepthSummary(seed); }

}  // namespace swarmbox::bus::testing
