// AgentNode: the thin node around the flight stack (STYLE.md 1). It joins the sim bus (sensor
// samples in, actuator commands out, lockstep: every sample is answered with a command for the
// same step) and the mesh bus (its DroneState for the neighbours; with raft.members, the drone's
// Raft node on the mission state, raft_host.hpp), runs FlightController on the
// samples' simulated time, lets a SetpointSource (the built-in plan now, the mission layer later)
// drive it, and prints logfmt events (`t=12.340 node=drone_3 event=hover ...`).
//
//   AgentOptions o;  o.name = "drone_3";  o.airframe_path = "trials/airframes/x500.yaml";
//   auto node = AgentNode::Create(o);           // bad airframe/plan/bus config: an error
//   Status s = node->Run();                     // until the plan is done and samples stop
#pragma once

#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

#include "flight_plan.hpp"
#include "mission_host.hpp"
#include "mission_options.hpp"
#include "raft_host.hpp"
#include "swarmbox/bus/participant.hpp"
#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/flight/flight_controller.hpp"
#include "swarmbox/radio/radio_link.hpp"

namespace swarmbox::agent {

struct AgentOptions {
  std::string name;                     // drone name, [A-Za-z0-9_]+
  std::string airframe_path;            // trials/airframes/<airframe>.yaml
  std::string middleware = "cyclonedds";
  std::string sim_interface = "lo";
  int sim_domain = 0;
  std::string mesh_interface = "lo";
  int mesh_domain = 1;
  bool mesh = true;                     // join the mesh (publish DroneState)
  std::string plan = "takeoff:5,hover:10,land";
  double preflight_s = 2.0;             // on the ground after the estimator is ready [sim s]
  bool has_start = false;               // the take-off spot (ground point under the drone)
  flight::Vec3 start_m = flight::Vec3::Zero();
  double payload_mass_kg = 0.0;         // initial load estimate
  bool swing_damping = true;
  double control_dt_s = 0.004;          // the physics server's lockstep period [s]
  std::chrono::milliseconds first_sample_timeout{10000};  // wall clock
  std::chrono::milliseconds stall_timeout{5000};          // wall clock, after the first sample
  bool exit_when_done = false;          // exit once the plan is complete (landed)
  std::FILE* log = stdout;              // logfmt events
  // Set (e.g. by a SIGTERM handler) to end Run() cleanly (Ok, event=stopped reason=signal) within
  // ~50 ms; nullptr: never. Must outlive the node.
  const volatile std::sig_atomic_t* stop = nullptr;
  // Raft on the mesh (raft_host.hpp): on when raft.members is not empty (needs `mesh`).
  // raft.self is set from `name`.
  RaftHostOptions raft;
  // What to fly (mission_options.hpp): the plan above, or the SAR mission (needs raft.members).
  MissionOptions mission;
  // Radio link measurement (agent/radio RadioLink): with the mesh and raft.members, ping every
  // other member every ping_every_ms of wall-clock time and log event=link per peer; 0 = off.
  int ping_every_ms = 200;
};

class AgentNode {
 public:
  static Result<std::unique_ptr<AgentNode>> Create(const AgentOptions& options);
  // Serves the lockstep until the samples stop (ok if the plan was completed by then) or, with
  // exit_when_done, until the plan is complete. kUnavailable when no sample ever arrives.
  // Also ends (Ok) when *options.stop is set. With Raft: also ends (the service's error) when the Raft storage failed (raft_failed()).
  Status Run();
  // True once the Raft service stopped because its storage failed: the agent must exit 1.
  bool raft_failed() const { return raft_ && raft_->stopped(); }

 private:
  AgentNode(AgentOptions options, flight::FlightController fc, FlightPlan plan);
  void Log(const LogEvent& e);
  void HandleSample(const bus::SensorSample& msg);
  // --mission sar: feeds the mission host (camera, peers, committed state) and carries out what
  // it asks (setpoint, payload world command, proposals, detections, events).
  void StepMission(const bus::SensorSample& msg, bool hover_event);
  bool Done() const;  // the plan is complete, or the SAR mission is (and this drone is down)

  AgentOptions options_;
  flight::FlightController fc_;
  FlightPlan plan_;
  std::unique_ptr<bus::Participant> sim_;
  std::unique_ptr<bus::Participant> mesh_;
  std::unique_ptr<bus::Subscriber<bus::SensorSample>> sensor_sub_;
  std::unique_ptr<bus::Publisher<bus::ActuatorCommand>> actuator_pub_;
  std::unique_ptr<bus::Publisher<bus::DroneState>> state_pub_;
  std::unique_ptr<RaftHost> raft_;  // after mesh_: destroyed before the participant
  std::unique_ptr<radio::RadioLink> radio_;  // likewise
  // --mission sar only.
  std::unique_ptr<MissionHost> mission_;
  std::unique_ptr<bus::Subscriber<bus::CameraImage>> camera_sub_;
  std::unique_ptr<bus::Publisher<bus::WorldCommand>> world_pub_;
  std::unique_ptr<bus::Publisher<bus::Detection>> detection_pub_;
  std::unique_ptr<bus::Subscriber<bus::DroneState>> peers_sub_;
  bus::CameraImage image_;
  bus::DroneState peer_;
  bus::WorldCommand world_cmd_;
  bus::Detection detection_;
  raft::MissionState committed_;   // refreshed from the Raft service at each mission tick
  bool leader_ = false;
  double next_committed_s_ = 0.0;
  bus::ActuatorCommand cmd_;
  bus::DroneState state_;
  bool have_step_ = false;
  std::uint64_t last_step_ = 0;
  double t_s_ = 0.0;
  double next_state_s_ = 0.0;
  std::size_t plan_index_logged_ = static_cast<std::size_t>(-1);
  bool plan_done_logged_ = false;
};

// Bus sample -> the flight stack's sample (the edge conversion).
flight::SensorSample FromBus(const bus::SensorSample& m);

}  // namespace swarmbox::agent
