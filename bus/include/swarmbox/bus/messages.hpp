// SwarmBox bus messages: plain C++ value types, one per IDL type in bus/idl/swarmbox.idl.
//
// These structs are what publishers and subscribers exchange (see participant.hpp). They mirror
// the IDL field for field (same names, same order, same types: `string` -> std::string,
// `sequence<T>` -> std::vector<T>, `T x[N]` -> std::array<T, N>, `octet` -> std::uint8_t) and
// carry no vendor types; each backend converts them to and from its generated types.
//
// Conventions (ARCHITECTURE.md): world frame ENU (x east, y north, z up) in metres, body frame
// FLU (x forward, y left, z up), quaternions (w,x,y,z) rotating body to world, SI units with the
// unit in the name. `sim_time_ns` is simulated time in nanoseconds since the start of the trial;
// `*_wall_ns` is wall-clock time in nanoseconds since the Unix epoch (CLOCK_REALTIME).
//
// Which topic and QoS each type travels on: see topics.hpp.
//
//   SensorSample s;
//   s.drone = "scout_1"; s.step = 42; s.imu.valid = true; s.imu.accel_m_s2 = {0, 0, 9.81};
//   publisher->Publish(s);
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace swarmbox::bus {

// ---- mesh domain: agent <-> agent (the radio; first: the sim domain carries them) -------------

// What a drone tells its neighbours about itself, on kDroneStateTopic with Qos::kState. Keyed on
// `drone`: a subscriber keeps the latest sample per drone.
struct DroneState {
  std::string drone;  // the key
  std::uint64_t seq = 0;
  std::int64_t sim_time_ns = 0;
  std::int64_t wall_time_ns = 0;
  std::array<double, 3> position_enu_m{};
  std::array<double, 3> velocity_enu_m_s{};
  double heading_rad = 0.0;       // yaw in world ENU: 0 = facing east, counter-clockwise positive
  double battery_fraction = 0.0;  // [0, 1]
  std::string mode;               // the agent's flight/mission mode, e.g. "search"
  bool operator==(const DroneState&) const = default;
};

// A Raft message, on kRaftTopic with Qos::kRadio (best effort: Raft retries; loss stays visible).
// The bus does not look inside `payload`.
struct RaftMessage {
  std::string from;
  std::string to;  // recipient drone name; subscribers drop messages not addressed to them
  std::uint64_t term = 0;
  std::vector<std::uint8_t> payload;
  bool operator==(const RaftMessage&) const = default;
};

// A perception result shared on the mesh, on kDetectionTopic with Qos::kRadio.
struct Detection {
  std::string from;  // the drone that saw it
  std::uint64_t seq = 0;
  std::int64_t sim_time_ns = 0;
  std::string label;        // e.g. "victim"
  double confidence = 0.0;  // [0, 1]
  std::array<double, 3> position_enu_m{};
  double position_sigma_m = 0.0;  // 1-sigma horizontal uncertainty of position_enu_m [m]
  bool operator==(const Detection&) const = default;
};

// Radio ping/pong for RTT and loss, on kRadioPingTopic with Qos::kRadio. A pong copies `seq`
// and `sent_ns` from its ping, swaps from/to and sets is_pong.
struct RadioPing {
  std::string from;
  std::string to;
  std::uint64_t seq = 0;
  // When the original ping was sent, on the radio's clock: simulated ns with radio.model channel,
  // the sender's steady clock with netem.
  std::int64_t sent_ns = 0;
  bool is_pong = false;
  bool operator==(const RadioPing&) const = default;
};

// A brain's own radio message (agent/brain: the brain SDK and the offboard interface): bytes under
// a topic the brain names. With radio.model netem on kBrainMessageTopic with Qos::kRadio; with
// channel inside a RadioFrame. The bus does not look inside `payload`.
struct BrainMessage {
  std::string from;
  std::string to;     // the receiving drone; "" = every drone in range
  std::string topic;  // the brain's name for the kind of message, e.g. "rendezvous/vote"
  std::vector<std::uint8_t> payload;
  bool operator==(const BrainMessage&) const = default;
};

// One frame on the simulated radio channel (radio.model: channel). An agent hands its frames to the
// physics server in its ActuatorCommand (radio_out, delivered_ns 0); the channel decides whether and
// when each arrives and hands it to each receiver in a SensorSample (radio_in, delivered_ns set), in
// the order (delivered_ns, from, seq). Exactly one of state_msg, detection_msg, raft_msg, ping_msg,
// brain_msg holds one element (the IDL is case-insensitive: `detection` would clash with the type Detection).
struct RadioFrame {
  std::string from;               // the sending drone
  std::string to;                 // the receiving drone; "" = broadcast to every drone in range
  std::uint64_t seq = 0;          // per sender, from 1, increasing
  std::int64_t sent_ns = 0;       // simulated time the sender handed it to the radio
  std::int64_t delivered_ns = 0;  // simulated time the channel delivered it (0 on the way out)
  std::uint32_t size_bytes = 0;   // bytes on the air (the channel charges airtime for them)
  std::vector<DroneState> state_msg;
  std::vector<Detection> detection_msg;
  std::vector<RaftMessage> raft_msg;
  std::vector<RadioPing> ping_msg;
  std::vector<BrainMessage> brain_msg;
  bool operator==(const RadioFrame&) const = default;
};

// ---- sim domain: physics server <-> agents ---------------------------------------------------

// A command to the world (fault injection), to the physics server on kWorldCommandTopic with
// Qos::kLockstep. The physics server owns the meaning of `command` and `args` and must reject
// (log) unknown ones; the names in use are
//   gps_dropout {duration_s}, gps_degrade {duration_s, h_acc_m, v_acc_m},
//   imu_bias_jump {ax, ay, az [m/s^2], gx, gy, gz [rad/s]}, wind_gust {vx, vy, vz [m/s], duration_s},
//   payload_attach {mass_kg}, payload_release {}.
struct WorldCommand {
  std::uint64_t seq = 0;          // per sender, increasing; lets the server drop duplicates
  std::int64_t sim_time_ns = 0;   // when to apply it; at or before the current time = now
  std::string target;             // drone name, or "" for the whole world (e.g. wind)
  std::string command;            // e.g. "gps_dropout"
  std::vector<double> args;       // numeric arguments, in the order documented for `command`
  bool operator==(const WorldCommand&) const = default;
};


// Simulated clock, published by the physics server once per step on topic kClockTopic.
struct ClockTick {
  std::uint64_t step = 0;           // control step counter, 0 at the start of the trial
  std::int64_t sim_time_ns = 0;     // simulated time at this step
  std::int64_t step_period_ns = 0;  // length of one control step (4'000'000 at 250 Hz)
  double rtf = 0.0;                 // real-time factor the server paces to (0 = as fast as possible)
  bool operator==(const ClockTick&) const = default;
};

// Inertial measurement in the body frame (FLU).
struct ImuSample {
  bool valid = false;
  std::array<double, 3> accel_m_s2{};  // specific force [m/s^2], body FLU (reads +9.81 z at rest)
  std::array<double, 3> gyro_rad_s{};  // angular rate [rad/s], body FLU
  double temperature_c = 0.0;          // sensor temperature [degC]
  bool operator==(const ImuSample&) const = default;
};

struct BaroSample {
  bool valid = false;
  double pressure_pa = 0.0;    // static pressure [Pa]
  double altitude_m = 0.0;     // pressure altitude above the world origin [m] (ENU z)
  double temperature_c = 0.0;  // [degC]
  bool operator==(const BaroSample&) const = default;
};

struct MagSample {
  bool valid = false;
  std::array<double, 3> field_gauss{};  // magnetic field [gauss], body FLU
  bool operator==(const MagSample&) const = default;
};

// GPS fix type, as u-blox/PX4 number them.
enum class GpsFix : std::uint8_t { kNone = 0, k2d = 2, k3d = 3 };

struct GpsSample {
  bool valid = false;  // false during a dropout: the other fields are then meaningless
  GpsFix fix_type = GpsFix::kNone;
  std::uint8_t num_satellites = 0;
  double latitude_deg = 0.0;   // WGS84
  double longitude_deg = 0.0;  // WGS84
  double altitude_m = 0.0;     // above mean sea level [m]
  // The same fix in the world ENU frame (origin = the world's geodetic origin) [m]; includes the
  // same noise/degradation as the geodetic fields.
  std::array<double, 3> position_enu_m{};
  std::array<double, 3> velocity_enu_m_s{};  // [m/s], world ENU
  double h_acc_m = 0.0;                      // 1-sigma horizontal accuracy [m]
  double v_acc_m = 0.0;                      // 1-sigma vertical accuracy [m]
  bool operator==(const GpsSample&) const = default;
};

struct BatterySample {
  bool valid = false;
  double voltage_v = 0.0;
  double current_a = 0.0;  // discharge current [A], positive when discharging
  double remaining = 0.0;  // state of charge [0, 1]
  bool operator==(const BatterySample&) const = default;
};

// One drone's sensors for one control step. Physics server -> agent, on
// SensorTopic(drone) with Qos::kLockstep. The agent answers with an ActuatorCommand carrying the
// same `step`.
struct SensorSample {
  std::string drone;  // drone name, e.g. "scout_1"
  std::uint64_t step = 0;
  std::int64_t sim_time_ns = 0;
  ImuSample imu;
  BaroSample baro;
  MagSample mag;
  GpsSample gps;
  BatterySample battery;
  // A CameraImage of this step was published before this sample (the agent takes it before it
  // steps, so perception sees the same frames at any speed).
  bool camera_frame = false;
  // A stereo pair of this step (a CameraImage on StereoTopic(drone), see CameraImage) was published
  // before this sample; only for an airframe with stereo enabled.
  bool stereo_frame = false;
  // radio.model channel: the frames the channel delivered to this drone in (previous step, this
  // step], in delivery order. Empty with radio.model netem.
  std::vector<RadioFrame> radio_in;
  bool operator==(const SensorSample&) const = default;
};

// Motor commands for one step. Agent -> physics server, on kActuatorTopic (every agent's answers on
// one topic) with Qos::kLockstep. Keyed by `drone` (the IDL's @key): one instance per drone, so the
// keep-last depth holds per drone and 100 answers of one step never push each other out.
struct ActuatorCommand {
  std::string drone;  // key: the answering drone; the physics server identifies the answer by it
  std::uint64_t step = 0;  // the SensorSample::step this command answers
  std::int64_t sim_time_ns = 0;
  bool armed = false;                 // false: motors off whatever motor_throttle says
  std::vector<double> motor_throttle;  // per motor, normalised [0, 1], in the airframe's motor order
  // This agent's Raft node leads (the physics server resolves a `raft_leader` fault target at its
  // simulated time from these: the drone that became leader last).
  bool raft_leader = false;
  // World commands of this step (payload attach/release), applied before the world steps.
  std::vector<WorldCommand> world;
  // radio.model channel: the frames this agent sends at this step (to the channel).
  std::vector<RadioFrame> radio_out;
  bool operator==(const ActuatorCommand&) const = default;
};

// Pinhole intrinsics of a camera image [pixels]; distortion is OpenCV's (k1, k2, p1, p2, k3).
struct CameraIntrinsics {
  double fx_px = 0.0;
  double fy_px = 0.0;
  double cx_px = 0.0;
  double cy_px = 0.0;
  std::array<double, 5> distortion{};
  bool operator==(const CameraIntrinsics&) const = default;
};

// A rigid pose in the world frame: position [m] ENU and the quaternion (w, x, y, z) rotating the
// frame named by the field that holds the Pose into world ENU.
struct Pose {
  std::array<double, 3> position_enu_m{};
  std::array<double, 4> orientation_wxyz{1.0, 0.0, 0.0, 0.0};
  bool operator==(const Pose&) const = default;
};

// A thermal frame (airframe `thermal:`, physics ThermalRenderer) is one CameraImage on
// CameraTopic(drone), published just before the colour frame it was taken with (same sim_time_ns
// and step): encoding kThermalEncoding, each pixel the apparent temperature in hundredths of a
// kelvin as an unsigned 16-bit little-endian count, row_stride_bytes = 2 width_px; intrinsics and
// camera_pose the thermal camera's own.
inline constexpr std::string_view kThermalEncoding = "mono16";

// One camera frame. Physics server -> agent, on CameraTopic(drone) with Qos::kLockstep (5 Hz,
// 320x240 mono8/bgr8, ~80 KB).
//
// A stereo pair (issue #23) is one CameraImage on StereoTopic(drone), Qos::kLockstep, published
// before the step's SensorSample (which then has stereo_frame = true):
//   encoding "mono8"; the left and right rectified NIR images of W x H pixels side by side: the
//   left in columns [0, W), the right in [W, 2W); width_px = 2 W, height_px = H,
//   row_stride_bytes = 2 W;
//   intrinsics: fx_px = fy_px = the focal length [px], cx_px, cy_px the LEFT camera's principal
//   point (as StereoFrame's cx_px, cy_px; the right image's columns are then x - W), distortion 0
//   (rectified);
//   camera_pose: the left camera's optical frame at the exposure (as for the RGB camera);
//   sim_time_ns, step: the step's time (the exposure) and the step.
// The baseline is the airframe's stereo.baseline_m (the agent reads the same airframe file).
struct CameraImage {
  std::string drone;
  std::uint64_t step = 0;  // the control step at which the image was captured
  std::int64_t sim_time_ns = 0;
  std::uint32_t width_px = 0;
  std::uint32_t height_px = 0;
  std::uint32_t row_stride_bytes = 0;  // bytes from one row to the next in `data`
  // "mono8", "bgr8", "rgb8" (OpenCV/ROS names), "16UC1" (a depth image: DepthImageTopic) or
  // kThermalEncoding (a thermal frame on CameraTopic)
  std::string encoding;
  CameraIntrinsics intrinsics;
  // Pose of the camera's optical frame (OpenCV convention: x right, y down, z along the optical
  // axis) at capture: position in world ENU and the rotation optical frame -> world.
  Pose camera_pose;
  std::vector<std::uint8_t> data;  // height_px * row_stride_bytes bytes, row-major, top row first
  bool operator==(const CameraImage&) const = default;
};


// ---- both domains ------------------------------------------------------------------------

struct KeyValue {
  std::string key;
  std::string value;
  bool operator==(const KeyValue&) const = default;
};

// A generic event (the bus form of a logfmt line: `t=.. node=.. event=.. k=v ...`), on
// kEventTopic with Qos::kRadio.
struct Event {
  std::string node;
  std::int64_t sim_time_ns = 0;
  std::string name;  // the logfmt `event`, e.g. "leader_elected"
  std::vector<KeyValue> fields;
  bool operator==(const Event&) const = default;
};

// ---- sim domain, agents -> the physics server's recorder --------------------------------------

// One measured radio link, as the agent's link probe last reported it (its event=link line).
struct TelemetryLink {
  std::string peer;
  double loss = 0.0;    // [0, 1], over the probe's last window
  double rtt_ms = 0.0;  // mean round trip [ms] on the radio's clock; NaN when none was answered
  bool operator==(const TelemetryLink&) const = default;
};

// One drone's search sector of the committed mission plan: a polygon in world ENU [m], as
// (x0, y0, x1, y1, ...).
struct TelemetrySector {
  std::string drone;
  std::vector<double> polygon_xy_m;
  bool operator==(const TelemetrySector&) const = default;
};

// What only the agent knows, for the recording (record/): on kTelemetryTopic with Qos::kState,
// keyed by `drone`, every 1/record.rate_hz of simulated time. Nothing in an agent waits for it and
// nothing decides on it: a lost or late one changes the recording, never the run. NaN = unset or
// unknown (a setpoint axis the flight stack does not hold, the flocking terms of a drone that is not
// flocking).
struct Telemetry {
  std::string drone;  // the key
  std::int64_t sim_time_ns = 0;
  // The flight stack's estimate (not the truth), world ENU.
  std::array<double, 3> position_enu_m{};
  std::array<double, 3> velocity_enu_m_s{};
  std::array<double, 4> attitude_wxyz{1.0, 0.0, 0.0, 0.0};
  std::string flight_mode;  // flight::FlightModeName
  // The setpoint the flight stack tracks (its shaped reference), world ENU.
  std::array<double, 3> setpoint_position_enu_m{};
  std::array<double, 3> setpoint_velocity_enu_m_s{};
  double setpoint_yaw_rad = 0.0;
  // The flocking terms of the last flocking step (swarm::Flocking, V18), horizontal [m/s].
  std::array<double, 3> flock_separation{};
  std::array<double, 3> flock_alignment{};
  std::array<double, 3> flock_cohesion{};
  std::array<double, 3> flock_sum{};
  std::string raft_role;  // follower, pre_candidate, candidate, leader; "" without Raft
  std::uint64_t raft_term = 0;
  std::string raft_leader;  // "" when none is known
  std::uint64_t raft_commit_index = 0;
  double battery_fraction = 0.0;  // [0, 1]
  std::string mission_stage;      // the brain's status ("scout/searching"), else the flight mode
  bool armed = false;
  bool landed = true;
  std::vector<TelemetryLink> links;        // the link probe's reports since the last telemetry
  std::vector<TelemetrySector> sectors;    // the committed plan; sent by the Raft leader only
  std::vector<Detection> detections;       // this drone's perception results since the last one
  std::vector<Event> events;               // every log event of this agent since the last one
  bool operator==(const Telemetry&) const = default;
};

// ---- sim domain, offboard: an agent's flight stack <-> a brain in its own process ------------
//
// brain: program. OffboardInputTopic(drone) carries BrainInput (agent -> brain) and
// OffboardOutputTopic(drone) BrainOutput (brain -> agent), both Qos::kLockstep. Every brain period
// the agent publishes one BrainInput stamped with the step's simulated time and waits for the
// BrainOutput with the same sim_time_ns before it answers the lockstep: a brain that keeps up gives
// the same run at any speed. The contract (timeouts, the failsafe, determinism):
// agent/brain/README.md; the same data as C++ values: swarmbox/brain/brain.hpp.

// The flight stack's estimate of its own drone (PX4 VehicleOdometry + VehicleStatus +
// BatteryStatus in one sample): estimated, not true, state.
struct VehicleState {
  std::string drone;
  std::uint64_t step = 0;
  std::int64_t sim_time_ns = 0;
  std::array<double, 3> position_enu_m{};
  std::array<double, 3> velocity_enu_m_s{};
  std::array<double, 4> attitude_wxyz{1.0, 0.0, 0.0, 0.0};  // body FLU -> world ENU
  std::array<double, 3> angular_rate_flu_rad_s{};
  double battery_fraction = 0.0;  // [0, 1]
  double battery_voltage_v = 0.0;
  // The flight stack's mode: init, idle, takeoff, hold, position, velocity, trajectory, land,
  // landed (flight::FlightModeName).
  std::string flight_mode;
  bool armed = false;
  bool landed = true;
  double payload_mass_kg = 0.0;   // what the brain last attached (0: none)
  double mass_estimate_kg = 0.0;  // the hover-thrust estimator's total mass [kg]
  bool operator==(const VehicleState&) const = default;
};

// One committed entry of the swarm's consensus log (Raft), in index order.
struct CommittedEntry {
  std::uint64_t index = 0;
  std::vector<std::uint8_t> data;
  bool operator==(const CommittedEntry&) const = default;
};

// Agent -> brain, once per brain period: everything that happened since the previous input.
struct BrainInput {
  std::string drone;
  std::int64_t sim_time_ns = 0;       // the step's simulated time: the brain's only clock
  VehicleState vehicle;
  std::vector<Event> flight_events;   // the flight stack's events (takeoff, hover, arrived, landed...)
  bool is_leader = false;             // this drone leads the consensus
  std::string leader;                 // who leads, as far as this drone knows ("" = nobody)
  std::vector<DroneState> neighbours; // the latest state heard from each other drone
  std::vector<BrainMessage> messages; // brain messages the radio delivered, in delivery order
  std::vector<CommittedEntry> committed;  // newly committed consensus entries, in index order
  std::vector<Detection> detections;  // this drone's perception results (geolocated)
  bool operator==(const BrainInput&) const = default;
};

// PX4 TrajectorySetpoint semantics in world ENU; NaN = unset. Per axis: a position controls it
// (velocity and acceleration then feed forward); else a velocity; else an acceleration. yaw, else
// yawspeed; both NaN keep the heading.
struct TrajectorySetpoint {
  std::array<double, 3> position_enu_m{};
  std::array<double, 3> velocity_enu_m_s{};
  std::array<double, 3> acceleration_enu_m_s2{};
  double yaw_rad = 0.0;
  double yawspeed_rad_s = 0.0;
  bool operator==(const TrajectorySetpoint&) const = default;
};

// A command to the flight stack: "arm", "disarm", "takeoff" (param: height above the start [m]),
// "land", "hold", "payload_attach" (param: mass [kg]), "payload_release".
struct VehicleCommand {
  std::string command;
  double param = 0.0;
  bool operator==(const VehicleCommand&) const = default;
};

// A proposal to the swarm's consensus log (committed entries come back in BrainInput::committed).
struct Proposal {
  std::vector<std::uint8_t> data;
  bool operator==(const Proposal&) const = default;
};

// Brain -> agent: the answer to the BrainInput with the same sim_time_ns. Also the offboard
// heartbeat: no answer for the offboard timeout and the drone fails safe.
struct BrainOutput {
  std::string drone;
  std::int64_t sim_time_ns = 0;                // the BrainInput it answers
  std::vector<TrajectorySetpoint> setpoint;    // none: keep the last one; at most one
  std::vector<VehicleCommand> commands;        // applied in order, before the setpoint
  std::vector<BrainMessage> messages;          // onto the radio
  std::vector<Proposal> proposals;             // to the consensus log
  std::string status;                          // broadcast in DroneState::mode
  std::vector<Event> events;                   // logged by the agent as logfmt lines
  bool operator==(const BrainOutput&) const = default;
};

// ---- sim domain, agents -> anyone: stereo depth (agent/depth, issue #23) -----------------------

// One depth frame of the drone's stereo camera in a few numbers (swarmbox::depth::DepthSummary):
// on kDepthTopic, keyed by drone, Qos::kState. Released by the agent the device's latency
// (30-50 ms of simulated time) after the exposure.
struct DepthSummary {
  std::string drone;
  std::int64_t capture_ns = 0;       // exposure (simulated time)
  std::int64_t sim_time_ns = 0;      // release: capture_ns + the device's latency
  double fill_rate = 0.0;            // share of pixels with depth [0, 1]
  double median_m = 0.0;             // median depth over them (0: none)
  double near_p5_m = 0.0;            // 5th percentile: the nearest surfaces
  std::uint32_t grid_cols = 0;
  std::uint32_t grid_rows = 0;
  std::vector<double> grid_m;        // grid_rows x grid_cols median depths, row-major; 0 = none
  Pose camera_pose;                  // left camera's optical frame at the exposure
  bool operator==(const DepthSummary&) const = default;
};

// ---- type registry (used by the API to pick the backend's generated type) -----------------

enum class MessageType : std::uint8_t {
  kClockTick,
  kSensorSample,
  kActuatorCommand,
  kCameraImage,
  kWorldCommand,
  kDroneState,
  kRaftMessage,
  kDetection,
  kRadioPing,
  kBrainMessage,
  kEvent,
  kBrainInput,
  kBrainOutput,
  kTelemetry,
  kDepthSummary,
};
inline constexpr int kMessageTypeCount = 15;

// The DDS type name on the wire, e.g. "swarmbox::msg::SensorSample".
std::string_view MessageTypeName(MessageType type);

template <typename T>
struct MessageTraits;  // only the top-level message types above are specialised

#define SWARMBOX_BUS_MESSAGE_TRAITS(T)                             \
  template <>                                                      \
  struct MessageTraits<T> {                                        \
    static constexpr MessageType kType = MessageType::k##T;        \
  }
SWARMBOX_BUS_MESSAGE_TRAITS(ClockTick);
SWARMBOX_BUS_MESSAGE_TRAITS(SensorSample);
SWARMBOX_BUS_MESSAGE_TRAITS(ActuatorCommand);
SWARMBOX_BUS_MESSAGE_TRAITS(CameraImage);
SWARMBOX_BUS_MESSAGE_TRAITS(WorldCommand);
SWARMBOX_BUS_MESSAGE_TRAITS(DroneState);
SWARMBOX_BUS_MESSAGE_TRAITS(RaftMessage);
SWARMBOX_BUS_MESSAGE_TRAITS(Detection);
SWARMBOX_BUS_MESSAGE_TRAITS(RadioPing);
SWARMBOX_BUS_MESSAGE_TRAITS(BrainMessage);
SWARMBOX_BUS_MESSAGE_TRAITS(Event);
SWARMBOX_BUS_MESSAGE_TRAITS(BrainInput);
SWARMBOX_BUS_MESSAGE_TRAITS(BrainOutput);
SWARMBOX_BUS_MESSAGE_TRAITS(Telemetry);
SWARMBOX_BUS_MESSAGE_TRAITS(DepthSummary);
#undef SWARMBOX_BUS_MESSAGE_TRAITS

template <typename T>
concept BusMessage = requires { MessageTraits<T>::kType; };

}  // namespace swarmbox::bus
