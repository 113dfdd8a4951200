// AgentNode: the thin node around the flight stack (STYLE.md 1). It joins the sim bus (sensor
// samples in, actuator commands out, lockstep: every sample is answered with a command for the
// same step), talks to the other drones through a radio::MeshRadio (its DroneState for the
// neighbours; with raft.members, the drone's Raft node on the mission state, raft_host.hpp, and
// the link probe), runs FlightController on the samples' simulated time, lets a SetpointSource
// (the built-in plan, or the SAR mission) or a brain (brain_host.hpp: --brain library|external)
// drive it, and prints logfmt events
// (`t=12.340 node=drone_3 event=hover ...`).
//
//   AgentOptions o;  o.name = "drone_3";  o.airframe_path = "trials/airframes/x500.yaml";
//   o.radio_model = RadioModel::kChannel;       // the physics server's simulated channel
//   auto node = AgentNode::Create(o);           // bad airframe/plan/bus config: an error
//   Status s = node->Run();                     // until the plan is done and samples stop
//
// One lockstep step k (sample k at t_k; ARCHITECTURE.md "Time"):
//   a. with sample.camera_frame, the CameraImage of step k is taken first (waited for; a wall
//      clock liveness bound of camera_timeout, event=camera_missing when it fires);
//   b. radio.TakeReceived -> DispatchFrames (radio_dispatch.hpp): Raft payloads to the Raft
//      service, pings/pongs to the link probe, DroneStates to the mission's peers;
//   c. flight step, Raft ticks and the link probe on the radio's clock, the mission (or plan, or
//      brain: every brain period, BrainHost) step, the DroneState broadcast (5 Hz of simulated
//      time; a brain's status as its mode), detections;
//   d. radio.Flush into the ActuatorCommand, cmd.world = this step's world commands (payload
//      attach/release), cmd.raft_leader; publish.
// Clocks: with RadioModel::kChannel every decision runs on the samples' simulated time (the
// radio's clock is the lockstep's; nothing happens between samples); with kNetem the radio, Raft
// and the probe run on the steady clock, also between samples (every 10 ms while waiting: the
// mesh does not wait for the lockstep), and the SAR leader's lost-member rule also wants a
// wall-clock silence (sar_brain.hpp: NetemWallClock, its one side channel).
// Wall clocks otherwise only bound liveness: the first sample, a stall, a missing camera frame,
// an external brain's answer (external_brain.hpp).
#pragma once

#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "brain_consensus.hpp"
#include "brain_host.hpp"
#include "brain_options.hpp"
#include "flight_plan.hpp"
#include "mission_options.hpp"
#include "depth_host.hpp"
#include "frame_wait.hpp"
#include "perception_host.hpp"
#include "radio_dispatch.hpp"
#include "raft_host.hpp"
#include "sar_brain.hpp"
#include "telemetry.hpp"
#include "swarmbox/bus/participant.hpp"
#include "swarmbox/common/log_tee.hpp"
#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/depth/drop_spot.hpp"
#include "swarmbox/flight/flight_controller.hpp"
#include "swarmbox/radio/link_probe.hpp"
#include "swarmbox/radio/mesh_radio.hpp"
#include "swarmbox/swarm/battery_model.hpp"

namespace swarmbox::agent {

// --radio-model: how the agent reaches the other drones.
enum class RadioModel {
  kNetem,    // the mesh DDS domain (radio::DdsRadio), impaired by netem on the wall clock
  kChannel,  // no mesh domain: frames ride the lockstep to the physics server's simulated channel
};
// "netem" | "channel" (kInvalidArgument otherwise), and back.
Result<RadioModel> ParseRadioModel(std::string_view text);
std::string_view RadioModelName(RadioModel model);

struct AgentOptions {
  std::string name;                     // drone name, [A-Za-z0-9_]+
  std::string airframe_path;            // trials/airframes/<airframe>.yaml
  std::string middleware = "cyclonedds";
  std::string sim_interface = "lo";
  int sim_domain = 0;
  // Discovery on the sim bus as a star (bus/cyclone_config.hpp): the hosts whose well-known
  // participant (index 0) the agent announces itself to, by unicast only: the physics server's
  // container and the drone's brain container. Empty: multicast discovery (a hand-started agent).
  std::vector<std::string> sim_peers;
  std::string mesh_interface = "lo";
  int mesh_domain = 1;
  bool mesh = true;                     // have a radio (publish DroneState); false: --no-mesh
  RadioModel radio_model = RadioModel::kNetem;  // channel: mesh_interface/mesh_domain unused
  std::string plan = "takeoff:5,hover:10,land";
  double preflight_s = 2.0;             // on the ground after the estimator is ready [sim s]
  bool has_start = false;               // the take-off spot (ground point under the drone)
  flight::Vec3 start_m = flight::Vec3::Zero();
  double payload_mass_kg = 0.0;         // initial load estimate
  bool swing_damping = true;
  double control_dt_s = 0.004;          // the physics server's lockstep period [s]
  // Wall clock: no first sample and no sign of the physics server (sim/status) for this long ends
  // the run (server_wait.hpp); each status of the server's start begins the wait afresh.
  std::chrono::milliseconds first_sample_timeout{10000};
  std::chrono::milliseconds stall_timeout{5000};          // wall clock, after the first sample
  std::chrono::milliseconds camera_timeout{5000};         // wall clock, a flagged camera frame
  bool exit_when_done = false;          // exit once the plan is complete (landed)
  std::FILE* log = stdout;              // logfmt events
  // Set (e.g. by a SIGTERM handler) to end Run() cleanly (Ok, event=stopped reason=signal) within
  // ~50 ms; nullptr: never. Must outlive the node.
  const volatile std::sig_atomic_t* stop = nullptr;
  // Raft over the radio (raft_host.hpp): on when raft.members is not empty (needs `mesh`); its
  // timings on the radio's clock (simulated ms with channel, wall ms with netem).
  // raft.self is set from `name`.
  RaftHostOptions raft;
  // What to fly (mission_options.hpp): the plan above, or the SAR mission (needs raft.members).
  MissionOptions mission;
  // Which brain flies (brain_options.hpp): builtin = `mission` above; library or external: a
  // brain::Brain through BrainHost (Context from name, raft.members, raft.seed, the airframe,
  // mission.world_path and mission.payload; Raft on its own state or the entry log).
  BrainOptions brain;
  // Radio link measurement (agent/radio LinkProbe): with a radio and raft.members, every
  // ping_every_ms of the radio's clock ping ping_peers other members (round-robin, those heard in
  // the last 5 s first) and log event=link per sampled peer; ping_every_ms 0 = off.
  int ping_every_ms = 200;
  int ping_peers = 3;  // > 0
  // The recording (telemetry.hpp): every 1/telemetry_hz of simulated time a bus::Telemetry on
  // sim/telemetry with every log line printed since the last one; 0 = none. Nothing decides on it.
  double telemetry_hz = 0.0;
};

class AgentNode final : private FrameHandler {
 public:
  static Result<std::unique_ptr<AgentNode>> Create(const AgentOptions& options);
  ~AgentNode() override;
  // Serves the lockstep until the samples stop (ok if the plan was completed by then) or, with
  // exit_when_done, until the plan is complete. kUnavailable when no sample ever arrives.
  // Also ends (Ok) when *options.stop is set. With Raft: also ends (the service's error) when
  // the Raft storage failed (raft_failed()).
  Status Run();
  // True once the Raft service stopped because its storage failed: the agent must exit 1.
  bool raft_failed() const { return raft_ && raft_->stopped(); }

 private:
  AgentNode(AgentOptions options, flight::FlightController fc, FlightPlan plan);
  void Log(const LogEvent& e);
  void LogReady();  // event=ready: what the node was started with
  // Run's wait for the next sample (the stall or the first-sample bound, in slices).
  class SampleWait;
  enum class Waited { kSample, kTimedOut, kStopped };
  // kStopped: stop requested (event=stopped logged). netem: serves the radio while it waits;
  // Raft's error.
  Result<Waited> WaitForSample(SampleWait& wait, bus::SensorSample& msg, bus::Event& status);
  // No sample for the wait's timeout: Ok when the run was over anyway (event=samples_stopped),
  // else why it ended early.
  Status SamplesStopped(const SampleWait& wait);
  // Takes the camera frames waiting; with msg.camera_frame, waits (camera_timeout) for the one
  // of this step. false: stop requested while waiting.
  bool TakeCamera(const bus::SensorSample& msg);
  Status HandleSample(const bus::SensorSample& msg);
  // HandleSample's parts, in its order.
  void TakeRadioFrames(const bus::SensorSample& msg);  // dispatched to the FrameHandler below
  FlightStatus StepFlight(const bus::SensorSample& msg);  // the command's motors, event lines
  void StepPlan(const FlightStatus& st);                  // the built-in plan
  void LogBattery();                                      // event=battery, brains
  void PublishAnswer();                                   // the step's ActuatorCommand
  // netem only, while waiting for a sample: the radio's deliveries dispatched, Raft's ticks and
  // the probe on the wall clock (as the mesh does not wait for the lockstep). Raft's error.
  Status ServeRadioBetweenSteps();
  // Raft's ticks due, then the link probe's round (its lines logged). Raft's error.
  Status StepRaftAndProbe();
  // --mission sar: perception (camera frames -> detections to the brain, also broadcast), netem's
  // wall clock for SarBrain's side channel, then StepBrain.
  void StepMission(const bus::SensorSample& msg);
  void OnThermalImage(const bus::CameraImage& image);  // a thermal frame to perception, in kelvin
  // With a stereo depth camera: the step's pairs into the device (posed by this step's estimate),
  // the depth frames due released (event=stereo_missing for a flagged pair that did not come).
  // false: stop requested while waiting.
  bool StepDepth(const bus::SensorSample& msg);
  // --mission sar, the lifter surveying its drop point: the newest depth frame exposed since it
  // asked, checked for a flat spot (depth::ChooseDropSpot), answered (event=drop_spot_survey).
  void AnswerDropSpot();
  // --brain library|external: the vehicle as the brain sees it, then the BrainHost step.
  void StepBrain(const bus::SensorSample& msg);
  void BroadcastState(const bus::SensorSample& msg);
  // Every 1/telemetry_hz of simulated time, after the step's answer: what only this agent knows,
  // for the recording. Decides nothing.
  void PublishTelemetry(const bus::SensorSample& msg);
  void FillTelemetrySetpoint(bus::Telemetry& t) const;
  void FillTelemetryRaft(bus::Telemetry& t);  // role, term, leader; the leader's plan when it changed
  bool Done() const;  // the plan is complete, or the SAR mission is (and this drone is down)
  // FrameHandler (radio_dispatch.hpp).
  void OnRaftPayload(std::span<const std::uint8_t> bytes) override;
  void OnPing(const bus::RadioFrame& frame) override;
  void OnState(const bus::DroneState& state, const bus::RadioFrame& frame) override;
  void OnDetection(const bus::Detection& detection, const bus::RadioFrame& frame) override;
  void OnBrainMessage(const bus::BrainMessage& message, const bus::RadioFrame& frame) override;
  void LogBrainEvent(const brain::Event& e);  // a brain's event line, at the agent's simulated time

  // Create's phases, in its order (agent_node_start.cpp). kInvalidArgument for what the user must
  // fix (exit 2), bus errors otherwise.
  struct Startup;  // the airframe model and what the brain and perception are made from
  static Result<Startup> LoadStartup(const AgentOptions& o);  // no bus joined yet
  static Result<std::unique_ptr<AgentNode>> MakeNode(const AgentOptions& o, const flight::FlightConfig& config);
  Status StartTelemetry();  // telemetry_hz > 0: the log's tee and the telemetry's clock
  Status JoinSimBus();      // the sim participant, the sensor and sim/status readers
  Status StartSimPublishers();  // sim/actuator; sim/telemetry with telemetry_hz > 0
  // The brain that flies (library, external or SarBrain) and its replicated state; null for the
  // built-in plan.
  Result<std::unique_ptr<brain::Brain>> MakeFlyingBrain(const Startup& s);
  // Creates the brain of options_.brain (library or external) with its Context, logs brain_loaded.
  Result<std::unique_ptr<brain::Brain>> MakeBrain(const flight::FlightConfig& config, int period_steps);
  Result<std::unique_ptr<brain::Brain>> LoadLibraryBrain(const brain::Context& ctx, LogEvent& loaded);
  Result<std::unique_ptr<brain::Brain>> StartExternalBrain(LogEvent& loaded);
  Status StartRadio(bool brain);  // with the mesh: the channel's radio or the mesh domain's
  Status StartRaft(bool brain);   // with raft.members
  std::unique_ptr<raft::StateMachine> RaftMachine(bool brain);  // what Raft replicates
  Status StartLinkProbe();
  void StartBrainHost(const Startup& s, std::unique_ptr<brain::Brain> brain);  // a brain or SarBrain
  Status StartPerception(const Startup& s);  // a SAR scout, or a brain on an airframe with a camera
  Status StartDepth(const Startup& s);       // an airframe with `stereo:` (the OAK-D Pro)
  static std::optional<depth::SlungPayload> SlungPayloadSeen(const Startup& s, const std::string& payload);

  class FlightAdapter;  // FlightPort over fc_

  // First: the log stream's tee outlives every part that prints to options_.log.
  EventQueue telemetry_events_;     // the log lines since the last telemetry
  std::unique_ptr<LogTee> log_tee_;  // telemetry_hz > 0: options_.log is its stream
  AgentOptions options_;
  flight::FlightController fc_;
  FlightPlan plan_;
  std::unique_ptr<bus::Participant> sim_;
  std::unique_ptr<bus::Participant> mesh_;  // netem only
  std::unique_ptr<bus::Subscriber<bus::SensorSample>> sensor_sub_;
  std::unique_ptr<bus::Subscriber<bus::Event>> status_sub_;  // sim/status: the server's start
  std::unique_ptr<bus::Publisher<bus::ActuatorCommand>> actuator_pub_;
  std::unique_ptr<radio::MeshRadio> radio_;   // after mesh_: destroyed before the participant
  SimClock sim_clock_;                        // the agent's simulated seconds (event lines)
  std::unique_ptr<RadioClock> raft_clock_;    // the radio's clock for Raft
  // --brain library|external: the brain's own replicated state (Raft's machine refers to it).
  std::unique_ptr<brain::ReplicatedState> brain_state_;
  std::unique_ptr<RaftHost> raft_;            // after radio_ and the clocks: destroyed first
  std::unique_ptr<radio::LinkProbe> probe_;
  std::vector<bus::RadioFrame> frames_;       // this step's deliveries
  DispatchCounts dispatched_;
  std::vector<LogEvent> lines_;
  // --brain library|external only (after sim_, radio_ and raft_: destroyed before them).
  std::unique_ptr<FlightPort> flight_port_;
  std::unique_ptr<RaftConsensus> consensus_;
  std::unique_ptr<BrainHost> brain_host_;
  std::optional<swarm::BatteryModel> battery_;  // the airframe's (x500, x8_heavy); none: 1.0
  brain::Vehicle vehicle_;
  // --mission sar only: SarBrain, the builtin brain, driven by brain_host_ like any other.
  SarBrain* sar_ = nullptr;                     // owned by brain_host_
  SarMissionState* sar_state_ = nullptr;        // brain_state_, typed: Raft's machine
  std::unique_ptr<PerceptionHost> perception_;  // scouts
  NetemWallClock netem_wall_;                   // netem only: the brain's side channel
  std::vector<brain::Detection> detections_;    // this step's
  std::unique_ptr<bus::Subscriber<bus::CameraImage>> camera_sub_;
  FrameBuffers camera_frames_;                // taken this step
  cv::Mat thermal_kelvin_;                    // a thermal frame in kelvin (reused)
  std::unique_ptr<DepthHost> depth_;          // an airframe with a stereo depth camera
  std::int64_t drop_spot_frame_ns_ = -1;      // the depth frame the last drop-spot answer used
  // The lifter's own slung payload as its depth camera sees it (masked out of the drop-spot
  // survey); none without a payload or a depth camera.
  std::optional<depth::SlungPayload> slung_payload_;
  bus::WorldCommand world_cmd_;
  bus::RadioFrame out_frame_;
  bus::ActuatorCommand cmd_;
  bus::DroneState state_;
  // The recording's telemetry (telemetry_hz > 0).
  std::unique_ptr<bus::Publisher<bus::Telemetry>> telemetry_pub_;
  TelemetryClock telemetry_clock_{0.0};
  bus::Telemetry telemetry_;
  std::vector<bus::Detection> telemetry_detections_;  // since the last telemetry
  double sectors_sent_s_ = -1e9;                       // when the leader last sent its plan
  std::vector<bus::TelemetrySector> sectors_scratch_;
  std::vector<bus::TelemetrySector> sectors_sent_;    // the plan last sent
  bool have_step_ = false;
  std::uint64_t last_step_ = 0;
  double t_s_ = 0.0;
  double next_state_s_ = 0.0;
  double next_battery_log_s_ = 0.0;  // event=battery, once per simulated second (brains)
  std::size_t plan_index_logged_ = static_cast<std::size_t>(-1);
  bool plan_done_logged_ = false;
};

// Bus sample -> the flight stack's sample (the edge conversion).
flight::SensorSample FromBus(const bus::SensorSample& m);

}  // namespace swarmbox::agent
