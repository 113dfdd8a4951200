// BrainHost: runs any brain (swarmbox/brain/brain.hpp) inside the agent: every brain period it
// assembles brain::Input from what the agent knows, calls Brain::Step, and applies the Output to
// the flight stack, the radio and the consensus log (ARCHITECTURE.md "Brains"). The SAR mission
// (SarBrain), a user's library brain and a brain in its own process (ExternalBrain) are all
// driven through it. Pure enough to test without DDS: the flight controller, the consensus log and
// the radio are reached through small interfaces (FlightPort, ConsensusPort, radio::MeshRadio).
//
//   BrainHost host(options, std::move(brain), flight, radio, consensus, stdout);
//   per lockstep step k at t_k, after the flight step and Raft's tick:
//     host.OnMessage / OnState (radio_dispatch), OnFlightEvent (fc.PopEvent), OnDetection
//     host.Step(k, t_k_ns, vehicle, &command.world);   // payload world commands appended
//     state.mode = host.status();                        // the DroneState broadcast
//
// One brain period (k % period_steps == 0):
//   Input:  t_ns; self = `vehicle` (the flight stack's estimate, battery, mode; payload_mass_kg as
//           this host last attached); flight events since the previous brain Step; is_leader and
//           leader from the consensus; neighbours = the newest DroneState (by sim_time_ns) of at
//           most `neighbours.max_listed` (--brain-neighbours, 32) other drones, the nearest ones,
//           sorted by name; drones silent for 3 s are forgotten (NeighbourTable, neighbour_table.hpp:
//           O(log N) per message, the nearest set chosen anew every 200 ms of simulated time, nothing
//           per step that grows with the swarm); brain messages delivered since the
//           previous Step, in delivery order; entries committed since the previous Step (the
//           consensus's tap, index order); detections since the previous Step.
//   Output, in this order: commands (takeoff/land/hold to the flight stack; payload_attach/
//           payload_release as this step's WorldCommands plus the load estimate, as the SAR lifter
//           did; arm is part of takeoff, disarm of landing: both logged as event=brain_rejected),
//           then the setpoint (PX4 TrajectorySetpoint semantics: flight::Setpoint::FromTrajectory;
//           the same setpoint again, NaN for NaN, is not commanded anew after the flight stack
//           accepted it and no command or failsafe action came between: a brain may stream it),
//           messages onto the radio as RadioFrames with brain_msg (from = self), proposals to the
//           consensus (dropped without one: event=brain_rejected what=proposal once), status for
//           the DroneState broadcast, events as logfmt lines `t=.. node=<self> event=<name> k=v`.
// The offboard failsafe (flight::OffboardFailsafe) sees every step whether the brain answered at
// it (an in-process brain always answers at its periods; a RemoteBrain may not): silent past the
// timeout -> hold, then land; while it holds or lands the brain's commands and setpoints are not
// flown (its messages, proposals, status and events still are). Its events are logged and also
// handed to the brain as flight events (offboard_lost, offboard_regained, offboard_failsafe).
// A brain whose Step throws (it must not) is logged (`event=brain_failed reason=..`) and never
// called again: it no longer answers, so the failsafe holds, then lands.
// Time: only the step's simulated time; nothing here reads a clock. Not thread-safe (the control
// loop owns it). Ownership: `flight`, `radio`, `consensus` and `log` outlive the host.
#pragma once

#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "neighbour_table.hpp"
#include "swarmbox/brain/brain.hpp"
#include "swarmbox/bus/messages.hpp"
#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/flight/offboard_failsafe.hpp"
#include "swarmbox/flight/setpoint.hpp"
#include "swarmbox/radio/mesh_radio.hpp"

namespace swarmbox::agent {

// The flight stack as BrainHost drives it (flight::FlightController in the agent).
class FlightPort {
 public:
  virtual ~FlightPort() = default;
  virtual bool Command(const flight::Setpoint& setpoint) = 0;  // false: rejected (an event says why)
  virtual void SetPayloadMass(double payload_mass_kg) = 0;     // the load estimate's prior [kg]
};

// The swarm's consensus log as a brain sees it (RaftHost in the agent).
class ConsensusPort {
 public:
  virtual ~ConsensusPort() = default;
  virtual bool is_leader() const = 0;
  virtual std::string leader() const = 0;  // "" when none is known
  // Appends the entries committed since the previous call, in index order.
  virtual void TakeCommitted(std::vector<brain::Entry>* out) = 0;
  // false: not accepted now (no leader known); the brain re-proposes what matters.
  virtual bool Propose(std::span<const std::uint8_t> data) = 0;
};

// A brain that may not answer (a brain in another process): after Step, answered() says whether
// `out` holds its answer for that input. An in-process brain always answers.
class RemoteBrain : public brain::Brain {
 public:
  virtual bool answered() const = 0;
};

struct BrainHostOptions {
  std::string self;                 // this drone's name
  int period_steps = 1;             // the brain runs at steps k with k % period_steps == 0 (>= 1)
  double offboard_timeout_s = 1.0;  // simulated: silent this long -> hold
  double offboard_hold_s = 5.0;     // simulated: then this long more -> land
  // The brain's own replicated state (Brain::MakeReplicatedState, kept by the consensus), handed
  // to every Step as Input::state; null: none.
  const brain::ReplicatedState* state = nullptr;
  // Input::neighbours: how many (the nearest), when a silent drone is forgotten.
  NeighbourTableOptions neighbours;
};

class BrainHost {
 public:
  // `radio` may be null (no mesh: messages are dropped, event=brain_rejected once); `consensus`
  // may be null (no --members: not leader, nothing committed, proposals dropped).
  BrainHost(BrainHostOptions options, std::unique_ptr<brain::Brain> brain, FlightPort& flight,
            radio::MeshRadio* radio, ConsensusPort* consensus, std::FILE* log);
  BrainHost(const BrainHost&) = delete;
  BrainHost& operator=(const BrainHost&) = delete;

  // The inbox, filled between two Steps.
  void OnMessage(const bus::BrainMessage& message);  // in delivery order
  void OnState(const bus::DroneState& state);        // another drone's broadcast, O(log N)
  void OnFlightEvent(const flight::FlightEvent& event);
  void OnDetection(const brain::Detection& detection);

  // One lockstep step (call every step): the brain's period when step % period_steps == 0, the
  // failsafe always. Appends the step's world commands (payload attach/release) to `world`.
  void Step(std::uint64_t step, std::int64_t t_ns, const brain::Vehicle& vehicle,
            std::vector<bus::WorldCommand>* world);

  const std::string& status() const { return status_; }  // the brain's last Output::status
  // The setpoint last commanded to the flight stack (NaN = unset); nullptr before the first.
  const brain::Setpoint* flown() const { return has_flown_ ? &flown_ : nullptr; }
  double payload_mass_kg() const { return payload_mass_kg_; }
  flight::OffboardFailsafe::Action failsafe() const { return failsafe_.action(); }
  std::uint64_t brain_steps() const { return brain_steps_; }  // Step calls of the brain that returned
  bool failed() const { return failed_; }
  std::uint64_t answers() const { return answers_; }          // ... that answered
  brain::Brain& brain() { return *brain_; }
  const NeighbourTable& neighbours() const { return neighbours_; }

 private:
  void BuildInput(std::int64_t t_ns, const brain::Vehicle& vehicle);
  // The brain's period: its Step on this Input (unless it failed), the inbox emptied; true when
  // it answered.
  bool StepBrain(std::int64_t t_ns, const brain::Vehicle& vehicle);
  // The failsafe after this step (its events logged and handed to the brain's next Input); a
  // change takes the flight stack over, in the air.
  flight::OffboardFailsafe::Action UpdateFailsafe(double t_s, bool answered, bool landed);
  // The Output: flown (fly: the failsafe is not in charge), sent, proposed, logged.
  void Apply(std::int64_t t_ns, std::vector<bus::WorldCommand>* world, bool fly);
  void Fly(std::int64_t t_ns, std::vector<bus::WorldCommand>* world);  // commands, then the setpoint
  void SendMessages(double t_s);
  void Propose(double t_s);
  void ApplyCommand(const brain::Command& c, std::int64_t t_ns, std::vector<bus::WorldCommand>* world);
  void Log(const LogEvent& e);
  void Reject(double t_s, const std::string& what, const std::string& reason);

  BrainHostOptions options_;
  std::unique_ptr<brain::Brain> brain_;
  RemoteBrain* remote_ = nullptr;  // brain_ when it is one
  FlightPort& flight_;
  radio::MeshRadio* radio_;
  ConsensusPort* consensus_;
  std::FILE* log_;
  flight::OffboardFailsafe failsafe_;

  // The inbox, since the previous brain Step.
  std::vector<brain::FlightEvent> flight_events_;
  NeighbourTable neighbours_;
  std::vector<brain::Message> messages_;
  std::vector<brain::Detection> detections_;
  // This period's Input storage and the Output (buffers reused).
  std::vector<brain::Entry> committed_;
  brain::Input in_;
  brain::Output out_;

  std::string status_;
  double payload_mass_kg_ = 0.0;
  std::uint64_t world_seq_ = 0;
  std::uint64_t brain_steps_ = 0;
  std::uint64_t answers_ = 0;
  brain::Setpoint flown_;  // the setpoint last commanded (has_flown_: and accepted since)
  bool has_flown_ = false;
  bool failed_ = false;  // the brain threw: never called again
  bool warned_radio_ = false;
  bool warned_consensus_ = false;
};

// brain::Vehicle::landed of a flight mode: init, idle and landed (on the ground, motors off).
bool LandedMode(flight::FlightMode mode);

// flight::FlightEvent -> brain::FlightEvent: name flight::FlightEventName, t_ns, fields x, y, z
// (2 decimals), and mode for mode_change.
brain::FlightEvent FlightEventOf(const flight::FlightEvent& e);

// Field for field, NaN equal to NaN.
bool SameSetpoint(const brain::Setpoint& a, const brain::Setpoint& b);

// brain::Setpoint -> the flight stack's (Setpoint::FromTrajectory of the same target).
flight::Setpoint FlightSetpointOf(const brain::Setpoint& sp);

}  // namespace swarmbox::agent
