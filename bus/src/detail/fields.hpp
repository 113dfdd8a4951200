// Field lists of every bus struct, in IDL order: the one place (besides the IDL and messages.hpp)
// that names the fields. Each backend expands them into its converters
// (C++ struct <-> generated type), so a field added to the IDL and messages.hpp but not here is
// not carried, and the round-trip tests in tests/bus fail for it.
//
// SWARMBOX_BUS_STRUCTS lists every struct in dependency order (nested types first).
#pragma once

#define SWARMBOX_BUS_FIELDS_ClockTick(F) F(step) F(sim_time_ns) F(step_period_ns) F(rtf)
#define SWARMBOX_BUS_FIELDS_ImuSample(F) F(valid) F(accel_m_s2) F(gyro_rad_s) F(temperature_c)
#define SWARMBOX_BUS_FIELDS_BaroSample(F) F(valid) F(pressure_pa) F(altitude_m) F(temperature_c)
#define SWARMBOX_BUS_FIELDS_MagSample(F) F(valid) F(field_gauss)
#define SWARMBOX_BUS_FIELDS_GpsSample(F)                                                       \
  F(valid) F(fix_type) F(num_satellites) F(latitude_deg) F(longitude_deg) F(altitude_m)        \
  F(position_enu_m) F(velocity_enu_m_s) F(h_acc_m) F(v_acc_m)
#define SWARMBOX_BUS_FIELDS_BatterySample(F) F(valid) F(voltage_v) F(current_a) F(remaining)
#define SWARMBOX_BUS_FIELDS_SensorSample(F) \
  F(drone) F(step) F(sim_time_ns) F(imu) F(baro) F(mag) F(gps) F(battery) F(camera_frame) F(stereo_frame) \
  F(radio_in)
#define SWARMBOX_BUS_FIELDS_ActuatorCommand(F) \
  F(drone) F(step) F(sim_time_ns) F(armed) F(motor_throttle) F(raft_leader) F(world) F(radio_out)
#define SWARMBOX_BUS_FIELDS_CameraIntrinsics(F) F(fx_px) F(fy_px) F(cx_px) F(cy_px) F(distortion)
#define SWARMBOX_BUS_FIELDS_Pose(F) F(position_enu_m) F(orientation_wxyz)
#define SWARMBOX_BUS_FIELDS_CameraImage(F)                                                     \
  F(drone) F(step) F(sim_time_ns) F(width_px) F(height_px) F(row_stride_bytes) F(encoding)     \
  F(intrinsics) F(camera_pose) F(data)
#define SWARMBOX_BUS_FIELDS_WorldCommand(F) F(seq) F(sim_time_ns) F(target) F(command) F(args)
#define SWARMBOX_BUS_FIELDS_DroneState(F)                                                      \
  F(drone) F(seq) F(sim_time_ns) F(wall_time_ns) F(position_enu_m) F(velocity_enu_m_s)          \
  F(heading_rad) F(battery_fraction) F(mode)
#define SWARMBOX_BUS_FIELDS_RaftMessage(F) F(from) F(to) F(term) F(payload)
#define SWARMBOX_BUS_FIELDS_Detection(F)                                                       \
  F(from) F(seq) F(sim_time_ns) F(label) F(confidence) F(position_enu_m) F(position_sigma_m)
#define SWARMBOX_BUS_FIELDS_RadioPing(F) F(from) F(to) F(seq) F(sent_ns) F(is_pong)
#define SWARMBOX_BUS_FIELDS_RadioFrame(F) \
  F(from) F(to) F(seq) F(sent_ns) F(delivered_ns) F(size_bytes) F(state_msg) F(detection_msg) F(raft_msg) F(ping_msg) \
  F(brain_msg)
#define SWARMBOX_BUS_FIELDS_BrainMessage(F) F(from) F(to) F(topic) F(payload)
#define SWARMBOX_BUS_FIELDS_VehicleState(F)                                                    \
  F(drone) F(step) F(sim_time_ns) F(position_enu_m) F(velocity_enu_m_s) F(attitude_wxyz)        \
  F(angular_rate_flu_rad_s) F(battery_fraction) F(battery_voltage_v) F(flight_mode) F(armed)    \
  F(landed) F(payload_mass_kg) F(mass_estimate_kg)
#define SWARMBOX_BUS_FIELDS_CommittedEntry(F) F(index) F(data)
#define SWARMBOX_BUS_FIELDS_BrainInput(F)                                                      \
  F(drone) F(sim_time_ns) F(vehicle) F(flight_events) F(is_leader) F(leader) F(neighbours)      \
  F(messages) F(committed) F(detections)
#define SWARMBOX_BUS_FIELDS_TrajectorySetpoint(F)                                              \
  F(position_enu_m) F(velocity_enu_m_s) F(acceleration_enu_m_s2) F(yaw_rad) F(yawspeed_rad_s)
#define SWARMBOX_BUS_FIELDS_VehicleCommand(F) F(command) F(param)
#define SWARMBOX_BUS_FIELDS_Proposal(F) F(data)
#define SWARMBOX_BUS_FIELDS_BrainOutput(F)                                                     \
  F(drone) F(sim_time_ns) F(setpoint) F(commands) F(messages) F(proposals) F(status) F(events)
#define SWARMBOX_BUS_FIELDS_KeyValue(F) F(key) F(value)
#define SWARMBOX_BUS_FIELDS_Event(F) F(node) F(sim_time_ns) F(name) F(fields)
#define SWARMBOX_BUS_FIELDS_TelemetryLink(F) F(peer) F(loss) F(rtt_ms)
#define SWARMBOX_BUS_FIELDS_TelemetrySector(F) F(drone) F(polygon_xy_m)
#define SWARMBOX_BUS_FIELDS_Telemetry(F)                                                       \
  F(drone) F(sim_time_ns) F(position_enu_m) F(velocity_enu_m_s) F(attitude_wxyz) F(flight_mode)  \
  F(setpoint_position_enu_m) F(setpoint_velocity_enu_m_s) F(setpoint_yaw_rad) F(flock_separation) \
  F(flock_alignment) F(flock_cohesion) F(flock_sum) F(raft_role) F(raft_term) F(raft_leader)      \
  F(raft_commit_index) F(battery_fraction) F(mission_stage) F(armed) F(landed) F(links)          \
  F(sectors) F(detections) F(events)
#define SWARMBOX_BUS_FIELDS_DepthSummary(F)                                                    \
  F(drone) F(capture_ns) F(sim_time_ns) F(fill_rate) F(median_m) F(near_p5_m) F(grid_cols)      \
  F(grid_rows) F(grid_m) F(camera_pose)

#define SWARMBOX_BUS_STRUCTS(S)                                                               \
  S(DroneState) S(RaftMessage) S(Detection) S(RadioPing) S(BrainMessage) S(RadioFrame)        \
  S(WorldCommand) S(ClockTick) S(ImuSample) S(BaroSample) S(MagSample) S(GpsSample)           \
  S(BatterySample) S(SensorSample) S(ActuatorCommand) S(CameraIntrinsics) S(Pose)             \
  S(CameraImage) S(KeyValue) S(Event) S(VehicleState) S(CommittedEntry) S(BrainInput)         \
  S(TrajectorySetpoint) S(VehicleCommand) S(Proposal) S(BrainOutput) S(TelemetryLink)        \
  S(TelemetrySector) S(Telemetry) S(DepthSummary)

// The top-level message types (those with a MessageType), for dispatch.
#define SWARMBOX_BUS_MESSAGES(M)                                                              \
  M(ClockTick) M(SensorSample) M(ActuatorCommand) M(CameraImage) M(WorldCommand)              \
  M(DroneState) M(RaftMessage) M(Detection) M(RadioPing) M(BrainMessage) M(Event)            \
  M(BrainInput) M(BrainOutput) M(Telemetry) M(DepthSummary)
