// SarBrain: SwarmBox's own search-and-rescue logic as a brain (agent/brain's SDK), the builtin
// brain of `--mission sar`. It sees only brain::Input and answers only brain::Output, like any
// user's brain: the proof that the SDK suffices (tests/agent/app/sar_brain_test.cpp steps it by
// hand on simulated time, without any bus).
//
// The agent runs it through BrainHost (brain_host.hpp) every lockstep step, exactly as a library
// brain; only the side channel below and the typed accessors (mode, complete) are SAR's own.
//
// What it does with the Input:
//   - its ReplicatedState is the committed mission (SarMissionState: raft::MissionState behind
//     raft::MissionStateMachine; entries are encoded raft::MissionCommands, its proposals too);
//   - neighbours (the host's nearest few, read once per mission tick): flocking, and the member
//     table from each one's status "<role>/<mode>" (e.g. "scout/searching", "lifter/on_ground";
//     its own Output::status likewise);
//   - messages on kStatusTopic: every member broadcasts its status on each change and every
//     status_every_s (1 s), so the leader's member table (swarm::MemberTable, O(1) per message)
//     holds every drone of a 100-drone swarm, not only the nearest the host hands it;
//   - is_leader: LeaderPlanner on the leader (Track on every drone);
//   - detections (the agent's PerceptionHost): sightings to report, scouts only;
//   - flight events (`hover`) and the flight mode: take-off, climb, landing;
//   - a per-airframe BatteryModel (battery_low -> return home, in the behaviours);
//   ScoutBehaviour or LifterSequence every mission tick (10 Hz of simulated time).
// And answers: take-off, land, payload_attach/payload_release commands; position setpoints
// (position only, only when the target changes) or flocking velocities (velocity only, every
// tick), PX4 TrajectorySetpoint form; proposals; the status; events (mission_start,
// sector_progress, payload_confirmed, mission_complete, ... as before the SDK).
//
//   auto brain = SarBrain::Create(ctx);               // kInvalidArgument: bad airframe/world/args
//   auto state = brain->MakeReplicatedState();         // Raft applies the committed entries to it
//   brain->Step(in, out);                              // every period (in.state == state.get())
//
// Context: self, members, airframe_path (battery model, camera, base height, mass, payloads),
// payload (non-empty: this drone is the lifter with that payload), world_path (the geofence),
// period_ns (the battery integrates over it), log (the mission state's event lines) and args:
// `start` "x,y,z" (the take-off spot, ground point [m, ENU]; absent: the first estimate minus the
// base height) and any MissionTuning field by name (e.g. member_timeout_s), as numbers.
//
// The one wall clock (netem only): the leader's lost-member rule also wants a wall-clock silence
// when the radio runs on the wall clock (leader_planner.hpp has why). brain::Input carries no wall
// clock, so the agent hands it through a SAR-private side channel, NetemWallClock, that only the
// node with --radio-model netem creates; with the channel (and in every test without it) the
// brain reads no wall clock at all and the simulated rule decides alone.
// Frames: world ENU [m]; time: Input::t_ns. Not thread-safe (the control loop owns it).
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "perception_host.hpp"
#include "swarmbox/airframe/airframe.hpp"
#include "swarmbox/brain/brain.hpp"
#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/raft/mission_state.hpp"
#include "swarmbox/raft/state_machine.hpp"
#include "swarmbox/swarm/member_table.hpp"
#include "swarmbox/swarm/swarm.hpp"

namespace swarmbox::agent {

// The brain message every SAR member broadcasts with its status (SarBrain::Step): payload
// "<t_ns> <role>/<mode> <x> <y>" (the sender's simulated time, its status as Output::status, its
// position [m, ENU, 2 decimals]), ~45 bytes.
inline constexpr std::string_view kStatusTopic = "sar/status";
std::string EncodeStatusMessage(std::int64_t t_ns, std::string_view status, double x_m, double y_m);
// false for anything else.
bool DecodeStatusMessage(std::string_view payload, std::int64_t* t_ns, std::string* status, double* x_m,
                         double* y_m);

// "<role>/<mode>" for Output::status (DroneState::mode), and back. Decode is false for anything
// else (the flight modes a --mission plan agent publishes, another brain's status, garbage).
std::string EncodeMissionMode(swarm::Role role, std::string_view mode);
bool DecodeMissionMode(std::string_view text, swarm::Role* role, std::string* mode);

// Tuning of the mission, chosen so sar_search completes well inside its 600 s timeout (see
// agent/app/README.md for the figures); every value has a reason next to it in sar_brain.cpp.
struct MissionTuning {
  double mission_dt_s = 0.1;            // behaviour tick [s]
  // Search area = geofence shrunk by this [m]. 0: the whole field. The lanes already end half a
  // footprint in from the area's edge (search_pattern.hpp), so the drones stay >= 11 m inside the
  // geofence at 30 m while the last frame of a lane reaches its edge; a margin of 8 m (until
  // 2026-11-28) left people within 8-9 m of the field's edge in no frame or only at a frame's
  // border (5 of the 12 people rubble20 missed that day: orchestrator/worlds places them up to
  // 7 m from the edge).
  double search_margin_m = 0.0;
  double scout_altitude_m = 30.0;       // above home [m]
  double scout_cruise_m_s = 7.0;
  double scout_takeoff_step_m = 3.0;    // flight-stack take-off height; then climb in position mode
  // Staggered take-off: scouts take off in 4 waves this far apart, by their place on a grid of
  // takeoff_grid_m (swarm::TakeoffWave has why) [s], [m].
  double takeoff_wave_s = 1.5;
  double takeoff_grid_m = 4.0;
  double scout_orbit_radius_m = 12.0;
  double scout_orbit_time_s = 20.0;     // a swept scout orbits a victim this long, then lands
  double lifter_transit_altitude_m = 10.0;
  double lifter_loading_time_s = 10.0;  // evacuee loaded onto the stretcher [s]
  double leader_start_timeout_s = 45.0; // start the search even if a member is still unheard
  // A member silent this long (simulated time) is gone; its sectors go to live scouts. The
  // search counts as finished only with the sector list unchanged this long (leader_planner.hpp
  // has the reasoning for 100 +- 20 ms radio delay and 5% loss) [s].
  double member_timeout_s = 6.0;
  // ... and silent this long on the wall clock too, netem only: at rtf 0 a radio or starvation
  // delay of ~1 s wall is many simulated seconds (leader_planner.hpp has the reasoning for 3 s) [s].
  double member_min_wall_s = 3.0;
  double assignment_settle_s = 10.0;
  double sighting_dedupe_m = 10.0;      // a sighting this close to a known victim is that victim
  // Every member sends its status (kStatusTopic) on each change and at least this often, so the
  // leader knows drones outside the neighbours the host hands it: 6 chances per member_timeout_s
  // (0.05^6 at 5% loss) for 1 frame/s per drone [s].
  double status_every_s = 1.0;
  // Load check (lifter): once lifted (attach height + load_check_climb_m) and load_check_delay_s
  // after an attach, the flight stack's mass estimate must show at least load_check_fraction of
  // the attached mass, or the hook is taken to be empty (event=payload_missing).
  // Safe height (scouts with a depth camera, issue #23): cruise at least this far above the
  // highest surface the depth camera sees under and around the scout (swarm::ScoutConfig
  // min_clearance_m; only surfaces within the OAK-D Pro's 15 m range are seen, so it matters for a
  // search flown low, e.g. scout_altitude_m 12 over 8 m trees) [m].
  double scout_min_clearance_m = 6.0;
  double load_check_climb_m = 3.0;
  double load_check_delay_s = 4.0;
  double load_check_fraction = 0.5;
  // Sightings: when a candidate is confirmed, rejected or revisited (swarm/sighting_fusion.hpp
  // has each default's reason); args fusion_<field> (e.g. fusion_min_baseline_m).
  // Close looks on: views from at most 21 m (the look altitude below and the revisit's 2 m
  // tolerance, + 1 m) are close looks, and only they confirm.
  swarm::FusionParams fusion{.close_look_height_m = 21.0};
  double revisit_look_s = 2.0;  // a revisit looks this long before it reports a miss [s]
  // A revisit descends to this height over the candidate to look (swarm::ScoutConfig::
  // revisit_look_altitude_m; at most the search altitude): 18 m is 3 m over the world generator's
  // tallest tree (15 m) and 26 px/m on the x500's camera, where the detector's precision on the
  // rubble fields is 0.93 against 0.86 at 30 m (BENCHMARKS.md "Perception: the close look");
  // 0: look from the search altitude (then fusion_close_look_height_m 0 too) [m].
  double revisit_look_altitude_m = 18.0;
};

struct SarBrainConfig {
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
  bool has_home = false;              // the take-off spot is known (args start); else first estimate
  flight::Vec3 home_m = flight::Vec3::Zero();  // ground point under the drone at start [m]
  double geofence_size_x_m = 200.0;
  double geofence_size_y_m = 200.0;
  airframe::CameraSpec camera;        // the sweep's footprint (scouts)
  // The airframe has a stereo depth camera (`stereo:`): the lifter surveys its drop point with it
  // (LifterConfig::survey_drop_point) and the agent answers drop_spot_query().
  bool depth_camera = false;
  double period_s = 0.004;            // between Steps (Context::period_ns) [s]
  MissionTuning tuning;
};

// The config from a brain::Context (the world file it names and its args) and the airframe the
// caller has parsed once (the agent's node: the same one its flight stack and perception use);
// kInvalidArgument naming the file, the flag or the arg otherwise. Where a ground payload lies is
// the airframe model's rule (airframe::PayloadOnGround), the one the physics server places it by.
Result<SarBrainConfig> SarBrainConfigFrom(const brain::Context& ctx, const airframe::Airframe& af);
// The same, parsing ctx.airframe_path first (a brain made from its Context alone).
Result<SarBrainConfig> SarBrainConfigFrom(const brain::Context& ctx);

// The args that tune the mission (MissionTuning's numbers and the fusion's two counts), in the
// order they are read: what a trial's `mission: {tuning: {...}}` may hold (`start` is not one).
std::vector<std::string> SarTuningKeys();

// The agent's --mission-tuning (the trial's mission.tuning as JSON, e.g. {"scout_altitude_m": 12})
// as Context args: a JSON object whose keys are SarTuningKeys() and whose values are numbers.
// kInvalidArgument naming the key (and, for an unknown one, the known ones) otherwise; an empty
// text is no tuning.
Result<std::map<std::string, std::string>> ParseMissionTuning(std::string_view json);

// The SAR-private side channel of the wall clock, netem only (banner). The node owns it, sets
// now_s before each Step and records, per drone, when its latest state (by simulated time) was
// taken off the radio; the brain only reads it.
struct NetemWallClock {
  struct Heard {
    std::int64_t t_ns = 0;   // the state's simulated time (Neighbour::t_ns)
    double wall_s = 0.0;     // when it was received, monotonic wall clock [s]
  };
  double now_s = std::numeric_limits<double>::quiet_NaN();  // monotonic wall clock now [s]
  std::map<std::string, Heard> heard;
  // A state of `drone` sent at t_ns received at wall_s: kept when no older than the one held.
  void OnState(const std::string& drone, std::int64_t t_ns, double wall_s);
};

// SarBrain's ReplicatedState: the committed raft::MissionState. Apply/Snapshot/Restore are
// raft::MissionStateMachine's; through this interface its event lines (mission_state,
// victim_confirmed, victim_status) go to the Context's log. The agent hands Raft the same machine
// directly (RaftMachine), so that Raft applies it with its own event lines, byte for byte as
// before the SDK (also the snapshot-installed line, which brain::ReplicatedState has no call for).
class SarMissionState final : public brain::ReplicatedState {
 public:
  explicit SarMissionState(std::function<void(const brain::Event&)> log);
  ~SarMissionState() override;
  void Apply(std::uint64_t index, std::span<const std::uint8_t> entry) override;
  std::vector<std::uint8_t> Snapshot() const override;
  bool Restore(std::span<const std::uint8_t> snapshot) override;
  const raft::MissionState& mission() const;
  // This state as Raft's state machine: a reference to its MissionStateMachine (this object must
  // outlive the Raft node that holds it).
  std::unique_ptr<raft::StateMachine> RaftMachine();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class SarBrain final : public brain::Brain {
 public:
  // `wall`: netem's side channel (outlives the brain); nullptr: none.
  static Result<std::unique_ptr<SarBrain>> Create(const brain::Context& ctx, const NetemWallClock* wall = nullptr);
  static Result<std::unique_ptr<SarBrain>> Create(const SarBrainConfig& config,
                                                  std::function<void(const brain::Event&)> log = {},
                                                  const NetemWallClock* wall = nullptr);

  std::unique_ptr<brain::ReplicatedState> MakeReplicatedState() override { return MakeMissionState(); }
  // The same, typed (the agent hands Raft its machine: SarMissionState::RaftMachine).
  std::unique_ptr<SarMissionState> MakeMissionState();
  // in.state must be this brain's SarMissionState (aborts otherwise: a wiring bug).
  void Step(const brain::Input& in, brain::Output& out) override;

  swarm::Role role() const { return role_; }
  // "<role>/<mode>", also Output::status.
  const std::string& mode() const { return mode_; }
  double battery_fraction() const { return battery_.fraction(); }
  bool payload_attached() const { return payload_attached_; }
  double payload_mass_kg() const { return payload_attached_ ? payload_mass_kg_ : 0.0; }
  // The committed mission is complete (event=mission_complete logged).
  bool complete() const { return complete_logged_; }
  // The lifter's drop-spot survey (issue #23): while its sequence holds over the drop point and
  // asks for the ground there (LifterSequence kSurveyDropPoint), what it asks: the default drop
  // point, the yaw the stretcher's length will lie along, the ground's height (home), the victim
  // and since when it asks (a depth frame exposed before then does not answer it).
  struct DropSpotQuery {
    Eigen::Vector2d default_xy_m = Eigen::Vector2d::Zero();
    double yaw_rad = 0.0;
    double ground_z_m = 0.0;
    Eigen::Vector2d victim_xy_m = Eigen::Vector2d::Zero();  // where the victim was confirmed
    double since_t_s = 0.0;
  };
  const std::optional<DropSpotQuery>& drop_spot_query() const { return drop_spot_query_; }
  // The answer from the depth camera (agent/app AgentNode with DepthHost), handed to the sequence
  // at its next mission tick.
  void AnswerDropSpot(const swarm::DropSpotAnswer& answer) { drop_spot_answer_ = answer; }
  // A scout's depth camera saw its highest surface around it at this world height (a new depth
  // frame; depth::ClearanceBelow); handed to the scout at its next mission tick.
  void ReportObstacleTop(double top_z_m) { obstacle_top_z_m_ = top_z_m; }
  // The last flocking step's terms (for the recording); nullptr while the drone is not flocking.
  const swarm::FlockingOutput* flocking() const { return flocking_ ? &flocking_out_ : nullptr; }

 private:
  // What one Step knows, in the behaviours' types.
  struct Now {
    double t_s = 0.0;
    double wall_s = std::numeric_limits<double>::quiet_NaN();
    std::string_view flight_mode;
    bool on_ground = true;
    flight::Vec3 pos_m = flight::Vec3::Zero();
    flight::Vec3 vel_m_s = flight::Vec3::Zero();
    double yaw_rad = 0.0;
    const raft::MissionState* mission = nullptr;
    bool is_leader = false;
    bool hover_event = false;
    double mass_estimate_kg = 0.0;
  };

  SarBrain(const SarBrainConfig& config, swarm::BatteryModel battery, std::function<void(const brain::Event&)> log,
           const NetemWallClock* wall);
  // The neighbours of this Input (at most the host's nearest few): the member table and the
  // flocking neighbours. Once per mission tick (and every Step until the mission starts).
  void OnNeighbours(const Now& now, std::span<const brain::Neighbour> neighbours);
  void OnStatus(const Now& now, const brain::Message& m);  // a kStatusTopic message: O(1)
  void SendStatus(const Now& now, brain::Output& out);     // on a change and every status_every_s
  Now ReadNow(const brain::Input& in) const;               // aborts when in.state is not a SarMissionState
  void OnDetections(const Now& now, std::span<const brain::Detection> detections);  // scouts: visible_
  void Start(const Now& now, brain::Output& out);  // builds the behaviour once the estimator is ready
  swarm::MissionInput BehaviourInput(const Now& now) const;
  void RunBehaviour(const Now& now, brain::Output& out);
  void RunLeader(const Now& now, brain::Output& out);        // the leader's planner and flock metrics
  void TrackDropSpotQuery(const Now& now);  // the lifter: drop_spot_query_ from its output
  void LogCompleteOnce(const Now& now, brain::Output& out);  // event=mission_complete
  void Drive(const Now& now, const swarm::SetpointRequest& sp, brain::Output& out);
  // Drive's take-off (a short take-off, then the climb) and flocking (a velocity every tick).
  void DriveTakeoff(const Now& now, const swarm::SetpointRequest& sp, bool changed, brain::Output& out);
  void DriveFlock(const Now& now, const swarm::SetpointRequest& sp, bool changed, brain::Output& out);
  void Apply(const swarm::PayloadRequest& p, brain::Output& out);
  void CheckLoad(const Now& now, brain::Output& out);

  SarBrainConfig config_;
  std::function<void(const brain::Event&)> log_;
  const NetemWallClock* wall_;
  swarm::Role role_ = swarm::Role::kScout;
  swarm::BatteryModel battery_;
  std::optional<swarm::ScoutBehaviour> scout_;
  std::optional<swarm::LifterSequence> lifter_;
  std::optional<swarm::LeaderPlanner> leader_;
  swarm::Flocking flock_;
  flight::Vec3 home_m_ = flight::Vec3::Zero();
  std::string mode_;

  // Every member's latest word (its DroneState when near, its status message otherwise): the
  // leader's roster. Updated per message, O(1) each.
  swarm::MemberTable members_;
  std::vector<swarm::NeighbourState> neighbours_;  // this tick's flocking neighbours (airborne)
  std::string sent_status_;                        // the status last sent in a status message
  std::string status_scratch_;                     // a received one, decoded (capacity kept)
  double status_due_s_ = 0.0;                      // the next periodic one [s]
  std::vector<swarm::GroundDetection> visible_;
  // The leader's event=flock_metrics, once per simulated second from members_ (pairs closer than
  // 3 m are unsafe; "united" within the flocking's 60 m sensing range).
  swarm::FlockMetricsLog flock_log_{{.separation_m = 3.0, .link_range_m = 60.0}};

  swarm::MissionOutput behaviour_out_;
  double next_tick_s_ = 0.0;
  bool payload_attached_ = false;
  double payload_mass_kg_ = 0.0;
  double attach_t_s_ = -1.0;  // >= 0: an attach waits for its load check
  // What was last sent to the flight stack (to send position/land/takeoff only on change).
  swarm::SetpointKind sent_kind_ = swarm::SetpointKind::kIdle;
  flight::Vec3 sent_target_m_ = flight::Vec3::Constant(1e9);
  bool climb_sent_ = false;
  bool complete_logged_ = false;
  std::optional<DropSpotQuery> drop_spot_query_;
  std::optional<swarm::DropSpotAnswer> drop_spot_answer_;
  std::optional<double> obstacle_top_z_m_;
  swarm::FlockingOutput flocking_out_;  // the last flocking step's (flocking_: of the last Drive)
  bool flocking_ = false;
};

// One LogEvent line (t, node, event, fields) as a brain::Event (event and fields; the host
// stamps t and node again when it prints it).
brain::Event ToBrainEvent(const LogEvent& e);

}  // namespace swarmbox::agent
