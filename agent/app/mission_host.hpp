// MissionHost: the SAR mission glue of swarmbox-agent (--mission sar), without any bus. AgentNode
// converts bus messages at its edge and calls this; everything here is plain values and simulated
// time, so the mission wiring is tested without DDS (tests/agent/app/mission_host_test.cpp).
//
// What it does with the agent's inputs:
//   - camera frames (scouts): VictimPerception (detector + geolocation with the *estimated* pose at
//     capture time + the simulated inference latency) -> detections, published on the mesh by the
//     node and fed to the behaviour;
//   - peers' DroneState: neighbours for flocking and the leader's roster (role and mode travel in
//     DroneState::mode as "<role>/<mode>", e.g. "scout/searching", "lifter/on_ground");
//   - the committed raft::MissionState and whether this node leads: ScoutBehaviour or
//     LifterSequence every mission tick (10 Hz of simulated time), LeaderPlanner on the leader
//     (its roster carries each peer's age on the simulated clock and, when the node passes wall
//     times, on the wall clock: a killed drone falls silent and its sectors are handed over, a
//     live one held back by the radio at rtf 0 does not; LeaderPlanner::Track runs on every drone);
//   - a per-airframe BatteryModel (battery_low -> return home, in the behaviours).
// And returns what the node must do: a flight setpoint (only when it changes, or each tick for a
// flocking velocity), a payload world command, Raft proposals, logfmt events and the mode string.
//
//   auto host = MissionHost::Create(config);          // kInvalidArgument: bad airframe/latency
//   host->RecordEstimate(t_s, est);                   // every control step (capture-time lookup)
//   host->OnCameraFrame(bgr, k, capture_t_s);         // each camera image (scouts)
//   host->OnPeerState(peer);                          // each DroneState of another drone
//   const MissionHostOutput& out = host->Step(in);    // every control step
//
// Time is simulated seconds, except the wall times (PeerState::received_wall_s,
// MissionHostInput::wall_s: a monotonic clock the node reads; NaN: none, the simulated clock alone
// decides who is lost). Frames: world ENU [m]. Not thread-safe (the control loop owns it).
#pragma once

#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/flight/estimator.hpp"
#include "swarmbox/flight/setpoint.hpp"
#include "swarmbox/raft/mission_state.hpp"
#include "swarmbox/swarm/swarm.hpp"

namespace swarmbox::agent {

// The downward camera of an airframe file (`camera:` mapping).
struct CameraSpec {
  int width_px = 320;
  int height_px = 240;
  double hfov_rad = 1.2;
  double rate_hz = 5.0;
  flight::Vec3 offset_m = flight::Vec3::Zero();  // camera centre in the body frame [m]
};
// kInvalidArgument (file:line:col) for a bad or missing `camera:` mapping.
Result<CameraSpec> LoadCameraSpec(const std::string& airframe_path);

// Where a payload that starts on the ground lies relative to the drone's spawn point, and its
// half height, from the airframe file: the physics server (World::AddDrone) lays it flat beside
// the drone, on the world -y side, (collision box y + payload y) / 2 + 0.5 m from the spawn.
struct GroundPayload {
  Eigen::Vector2d offset_m = Eigen::Vector2d::Zero();  // from the spawn point, world ENU [m]
  double half_height_m = 0.0;
};
Result<GroundPayload> LoadGroundPayload(const std::string& airframe_path, const std::string& payload);

// "<role>/<mode>" for DroneState::mode, and back. Decode is false for anything else (the flight
// modes a --mission plan agent publishes, garbage).
std::string EncodeMissionMode(swarm::Role role, std::string_view mode);
bool DecodeMissionMode(std::string_view text, swarm::Role* role, std::string* mode);

// A peer as heard on the mesh state topic.
struct PeerState {
  std::string name;
  std::string mode;                  // DroneState::mode as received
  flight::Vec3 position_m = flight::Vec3::Zero();
  flight::Vec3 velocity_m_s = flight::Vec3::Zero();
  double sim_time_s = 0.0;           // the sample's simulated time [s]
  // When this node took it off the bus, monotonic wall clock [s]; NaN: unknown.
  double received_wall_s = std::numeric_limits<double>::quiet_NaN();
};

// Tuning of the mission, chosen so sar_search completes well inside its 600 s timeout (see
// agent/app/README.md for the figures); every value has a reason next to it in mission_host.cpp.
struct MissionTuning {
  double mission_dt_s = 0.1;            // behaviour tick [s]
  double search_margin_m = 8.0;         // search area = geofence shrunk by this [m]
  double scout_altitude_m = 30.0;       // above home [m]
  double scout_cruise_m_s = 7.0;
  double scout_takeoff_step_m = 3.0;    // flight-stack take-off height; then climb in position mode
  double scout_orbit_radius_m = 12.0;
  double scout_orbit_time_s = 20.0;     // a swept scout orbits a victim this long, then lands
  double lifter_transit_altitude_m = 10.0;
  double lifter_loading_time_s = 10.0;  // evacuee loaded onto the stretcher [s]
  double leader_start_timeout_s = 45.0; // start the search even if a member is still unheard
  // A member silent this long (simulated time) is gone; its sectors go to live scouts. The
  // search counts as finished only with the sector list unchanged this long (leader_planner.hpp
  // has the reasoning for 100 +- 20 ms radio delay and 5% loss) [s].
  double member_timeout_s = 6.0;
  // ... and silent this long on the wall clock too: at rtf 0 a radio or starvation delay of ~1 s
  // wall is many simulated seconds (leader_planner.hpp has the reasoning for 3 s) [s].
  double member_min_wall_s = 3.0;
  double assignment_settle_s = 10.0;
  double sighting_dedupe_m = 10.0;      // a sighting this close to a known victim is that victim
  double max_tilt_for_perception_rad = 0.2;   // frames taken more tilted are not used
  double max_rate_for_perception_rad_s = 0.5; // nor while turning faster
  // Load check (lifter): once lifted (attach height + load_check_climb_m) and load_check_delay_s
  // after an attach, the flight stack's mass estimate must show at least load_check_fraction of
  // the attached mass, or the hook is taken to be empty (event=payload_missing).
  double load_check_climb_m = 3.0;
  double load_check_delay_s = 4.0;
  double load_check_fraction = 0.5;
};

struct MissionHostConfig {
  std::string name;
  std::vector<std::string> members;   // every drone of the trial (same list on each)
  std::string airframe;               // airframe name ("x500", "x8_heavy"): battery model
  std::string payload;                // non-empty: this drone is the lifter with that payload
  double payload_sling_length_m = 4.0;
  flight::Vec3 payload_hook_m{0.0, 0.0, -0.4};
  double payload_half_height_m = 0.125;
  Eigen::Vector2d payload_offset_m = Eigen::Vector2d::Zero();  // where it lies, from home [m]
  double base_height_m = 0.23;
  double vehicle_mass_kg = 0.0;       // empty airframe (the load check compares the estimate)
  bool has_home = false;              // the take-off spot is known (--start); else first estimate
  flight::Vec3 home_m = flight::Vec3::Zero();  // ground point under the drone at start [m]
  double geofence_size_x_m = 200.0;
  double geofence_size_y_m = 200.0;
  CameraSpec camera;
  double inference_latency_s = 0.040;
  MissionTuning tuning;
};

struct MissionHostInput {
  double t_s = 0.0;
  double wall_s = std::numeric_limits<double>::quiet_NaN();  // monotonic wall clock now [s]; NaN: none
  double dt_s = 0.004;                           // since the previous Step [s]
  flight::FlightMode flight_mode = flight::FlightMode::kInit;
  const flight::StateEstimate* estimate = nullptr;  // never null
  const raft::MissionState* mission = nullptr;      // committed; never null
  bool is_leader = false;
  bool hover_event = false;                      // the flight stack reported `hover` this step
  double mass_estimate_kg = 0.0;                 // the flight stack's hover-thrust mass estimate
};

struct MissionHostOutput {
  std::optional<flight::Setpoint> command;       // for FlightController::Command
  swarm::PayloadRequest payload;                 // for a sim/world_command
  std::vector<raft::MissionCommand> proposals;   // for RaftService::Propose
  std::vector<LogEvent> events;                  // one logfmt line each
  std::vector<swarm::GroundDetection> detections;  // newly visible: publish as bus::Detection
  bool mission_tick = false;                     // the behaviours ran at this step
  void Clear();
};

class MissionHost {
 public:
  static Result<std::unique_ptr<MissionHost>> Create(const MissionHostConfig& config);

  swarm::Role role() const { return role_; }
  // "<role>/<mode>" for DroneState::mode.
  const std::string& mode() const { return mode_; }
  double battery_fraction() const { return battery_.fraction(); }
  bool payload_attached() const { return payload_attached_; }
  double payload_mass_kg() const { return payload_attached_ ? payload_mass_kg_ : 0.0; }
  bool complete() const { return complete_logged_; }

  void RecordEstimate(double t_s, const flight::StateEstimate& est);
  // Runs perception on one frame; scouts only (a lifter ignores frames). Frames older than the
  // estimate history (~0.5 s) are dropped.
  void OnCameraFrame(const cv::Mat& bgr, const swarm::PinholeIntrinsics& k, double capture_t_s);
  void OnPeerState(const PeerState& peer);

  const MissionHostOutput& Step(const MissionHostInput& in);

 private:
  explicit MissionHost(const MissionHostConfig& config, swarm::BatteryModel battery);
  void Start(const MissionHostInput& in);  // builds the behaviour once the estimator is ready
  void RunBehaviour(const MissionHostInput& in);
  void Drive(const MissionHostInput& in, const swarm::SetpointRequest& sp);
  void Apply(const swarm::PayloadRequest& p);
  void Roster(double t_s, double wall_s, const flight::Vec3& own_position_m,
              std::vector<swarm::RosterEntry>* out) const;

  MissionHostConfig config_;
  swarm::Role role_ = swarm::Role::kScout;
  swarm::BatteryModel battery_;
  swarm::VictimPerception perception_;
  std::optional<swarm::ScoutBehaviour> scout_;
  std::optional<swarm::LifterSequence> lifter_;
  std::optional<swarm::LeaderPlanner> leader_;
  swarm::Flocking flock_;
  flight::Vec3 home_m_ = flight::Vec3::Zero();
  std::string mode_;

  struct Estimate {
    double t_s = -1.0;
    flight::Vec3 pos_m = flight::Vec3::Zero();
    flight::Quat att = flight::Quat::Identity();
    flight::Vec3 rate_radps = flight::Vec3::Zero();
  };
  std::vector<Estimate> history_;  // ring, one entry per control step
  std::size_t history_next_ = 0;

  std::map<std::string, PeerState> peers_;
  std::vector<swarm::NeighbourState> neighbours_;
  std::vector<swarm::GroundDetection> visible_;

  MissionHostOutput out_;
  swarm::MissionOutput behaviour_out_;
  double next_tick_s_ = 0.0;
  bool payload_attached_ = false;
  double payload_mass_kg_ = 0.0;
  double attach_t_s_ = -1.0;  // >= 0: an attach waits for its load check
  void CheckLoad(const MissionHostInput& in);
  // What was last sent to the flight stack (to send position/land/takeoff only on change).
  swarm::SetpointKind sent_kind_ = swarm::SetpointKind::kIdle;
  flight::Vec3 sent_target_m_ = flight::Vec3::Constant(1e9);
  bool climb_sent_ = false;
  bool complete_logged_ = false;
  std::uint32_t victims_logged_ = 0;
};

}  // namespace swarmbox::agent
