// The one place where the brain SDK's C++ values (swarmbox/brain/brain.hpp) and the offboard bus
// messages (bus::BrainInput / bus::BrainOutput, bus/idl/swarmbox.idl) are converted into each
// other, field for field: ExternalBrain (agent -> a brain in its own process), BrainHost (radio
// frames, neighbour states) and the test brain processes use these and nothing else.
//
//   bus::BrainInput wire;   ToBus(in, "scout_1", &wire);          // agent side
//   InputBuffers buf;       FromBus(wire, &buf);  brain->Step(buf.input, out);   // brain side
//   bus::BrainOutput answer; ToBus(out, "scout_1", wire.sim_time_ns, &answer);
//   Status s = FromBus(answer, &out);          // an unknown command name: kInvalidArgument
//
// Units and frames are the same on both sides (world ENU [m], body FLU, simulated ns); NaN means
// "unset" in a setpoint on both. Nothing here allocates beyond the destination's vectors.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/brain/brain.hpp"
#include "swarmbox/bus/messages.hpp"
#include "swarmbox/common/result.hpp"

namespace swarmbox::agent {

// The inverse of brain::CommandName: "takeoff" -> kTakeoff; kInvalidArgument listing the names.
Result<brain::Command::Kind> ParseCommandName(std::string_view name);

brain::Neighbour NeighbourFromBus(const bus::DroneState& state);
brain::Message MessageFromBus(const bus::BrainMessage& message);
bus::BrainMessage MessageToBus(const brain::Message& message);
brain::Detection DetectionFromBus(const bus::Detection& detection);
bus::Detection DetectionToBus(const brain::Detection& detection, const std::string& from);
bus::VehicleState VehicleToBus(const brain::Vehicle& vehicle, std::int64_t t_ns);
brain::Vehicle VehicleFromBus(const bus::VehicleState& vehicle);
bus::TrajectorySetpoint SetpointToBus(const brain::Setpoint& setpoint);
brain::Setpoint SetpointFromBus(const bus::TrajectorySetpoint& setpoint);

// brain::Input -> bus::BrainInput for `drone` (neighbours as DroneStates with their status in
// `mode`; flight events as bus::Events with node = drone).
void ToBus(const brain::Input& in, const std::string& drone, bus::BrainInput* out);

// A brain::Input over its own storage (Input holds spans): what a brain process hands its brain.
struct InputBuffers {
  brain::Input input;
  std::vector<brain::FlightEvent> flight_events;
  std::vector<brain::Neighbour> neighbours;
  std::vector<brain::Message> messages;
  std::vector<brain::Entry> committed;
  std::vector<brain::Detection> detections;
};
void FromBus(const bus::BrainInput& in, InputBuffers* out);

// brain::Output -> bus::BrainOutput answering the input of `t_ns`.
void ToBus(const brain::Output& out, const std::string& drone, std::int64_t t_ns, bus::BrainOutput* wire);
// bus::BrainOutput -> brain::Output (replaced). kInvalidArgument for an unknown command name or
// more than one setpoint; `out` then holds what came before the bad element.
Status FromBus(const bus::BrainOutput& wire, brain::Output* out);

}  // namespace swarmbox::agent
