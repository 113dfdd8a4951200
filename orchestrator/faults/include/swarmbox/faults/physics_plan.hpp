// Sensor and environment faults (gps_dropout, gps_degrade, imu_bias, wind_gust) as the world commands the
// physics server takes on the sim bus (physics_server/app/world_commands.hpp), planned purely. The
// runner carries each one out as `swarmbox-physics --send-command <target> <command> <args...>`
// exec'd in the physics container (the orchestrator links no DDS); mechanism "physics-command".
//
//   PhysicsPlan plan = PlanPhysicsFault(fault, {"scout_1"});
//   // fault {at: 8s, duration: 3s, gps_dropout: scout_1}:
//   //   apply {scout_1, gps_dropout, [3]}, undo {}: the server restores the fix after 3 s itself
//   // fault {at: 9s, duration: 4s, gps_degrade: {target: scout_1, h_acc_m: 5, v_acc_m: 8}}:
//   //   apply {scout_1, gps_degrade, [4, 5, 8]} (duration_s, h_acc_m, v_acc_m), undo {}
//
// Undo: gps_dropout, gps_degrade and wind_gust carry their duration (the server ends them on its own, in
// simulated time; no duration = kUntilEndS); imu_bias with a duration is undone by the negated
// jump, without one it stays.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "swarmbox/faults/fault_spec.hpp"

namespace swarmbox::faults {

// "For the rest of the trial" in a command that needs a duration [s] (about 11.6 days).
inline constexpr double kUntilEndS = 1e6;

// One WorldCommand {target, command, args}; target "" = the whole world.
struct WorldCommandCall {
  std::string target;
  std::string command;
  std::vector<double> args;
  bool operator==(const WorldCommandCall&) const = default;
};

struct PhysicsPlan {
  std::vector<WorldCommandCall> apply;
  std::vector<WorldCommandCall> undo;
};

// Whether the fault is carried out by the physics server.
bool IsPhysicsFault(const Fault& fault);
// `targets`: the resolved drones (ignored for wind_gust). Empty plan for other kinds.
PhysicsPlan PlanPhysicsFault(const Fault& fault, const std::vector<std::string>& targets);
// The wind a gust adds, world ENU [m/s]: `direction_deg` is where it blows FROM, clockwise from
// north, so a 270 deg (westerly) wind blows towards +x (east).
std::array<double, 3> GustVelocityEnu(const WindGust& gust);
// "gps_dropout scout_1 3" ("-" for the world), for messages.
std::string WorldCommandText(const WorldCommandCall& call);

}  // namespace swarmbox::faults
