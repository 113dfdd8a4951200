// swarmbox_swarm: the agent's pure mission libraries, and how swarmbox-agent (agent/app) wires
// them. Everything here takes inputs and simulated time and returns outputs: no DDS, threads or
// wall clock. Each header has its own banner; this one shows the whole loop.
//
//   flocking.hpp          Flocking              velocity setpoint from neighbours + goal (V18 Boids)
//   flock_metrics.hpp     ComputeFlockMetrics   safety / order / union of a swarm snapshot
//   search_pattern.hpp    PartitionArea (grid), PartitionOrder, LawnmowerWaypoints, OrbitWaypoints,
//                         GroundFootprint
//   battery_model.hpp     BatteryModel          energy, energy-to-home, battery_low
//   mission_types.hpp     MissionInput / MissionOutput / SetpointRequest / PayloadRequest
//   scout_behaviour.hpp   ScoutBehaviour        scout state machine
//   lifter_sequence.hpp   LifterSequence        x8_heavy stretcher rescue state machine
//   leader_planner.hpp    LeaderPlanner         what the Raft leader proposes
//   member_table.hpp      MemberTable           every member's latest word, per message, O(1)
//   victim_perception.hpp VictimPerception      detector + geolocation + latency queue
//
// Wiring sketch (agent/app; `driver` is the raft NodeDriver, `flight` the flight stack):
//
//   // start-up
//   swarm::ScoutBehaviour scout({.name = me, .home_m = spawn, .lifter_present = trial_has_x8});
//   swarm::Flocking flock(swarm::FlockingParams{}, swarm::Geofence::Centered(sx, sy), obstacles);
//   swarm::BatteryModel battery(*swarm::BatterySpecFor(airframe_name));
//   swarm::VictimPerception perception({.latency_s = trial_latency_s});
//   swarm::LeaderPlanner leader({.name = me, .search_area = area});
//
//   // on bus::CameraImage (5 Hz): perception.ProcessFrame(bgr, k, OpticalPoseFromBody(...), t_img)
//
//   // every control step (dt):
//   battery.Step(dt, est.vel_m_s, payload_kg, airborne);
//   detections.clear(); perception.PopVisible(now, &detections);   // publish as bus::Detection
//   in = {now, &driver.mission(), est.pos_m, est.vel_m_s, yaw, battery.fraction(),
//         battery.IsLow(dist_home, height, payload_kg), payload_attached, detections};
//   scout.Step(in, &out);                                // or lifter.Step(in, &out)
//   leader.Track(now, driver.mission());                 // every drone: sector list changes
//   if (driver.is_leader()) leader.Step(now, driver.mission(), roster_from_drone_states, &out);
//   // (roster: name, role, mode and age of each drone's latest DroneState: a silent one is gone)
//   for (auto& c : out.proposals) driver.Propose(c);
//   for (auto& e : out.events) std::puts(e.str().c_str());
//   if (out.payload.action != PayloadAction::kNone) publish bus::WorldCommand payload_attach/release
//   switch (out.setpoint.kind) {
//     case SetpointKind::kFlock:  flight.Velocity(flock.Step({est.pos_m, est.vel_m_s,
//                                   out.setpoint.target_m, neighbours}, dt).velocity_m_s, yaw); ...
//     case SetpointKind::kPosition: flight.Position(out.setpoint.target_m, out.setpoint.yaw_rad); ...
//     case SetpointKind::kTakeoff / kLand / kIdle: flight.Takeoff / Land / Disarm ...
//   }
//   publish bus::DroneState{..., mode = out.mode}
#pragma once

#include "swarmbox/swarm/battery_model.hpp"
#include "swarmbox/swarm/flock_metrics.hpp"
#include "swarmbox/swarm/flocking.hpp"
#include "swarmbox/swarm/leader_planner.hpp"
#include "swarmbox/swarm/lifter_sequence.hpp"
#include "swarmbox/swarm/member_table.hpp"
#include "swarmbox/swarm/mission_types.hpp"
#include "swarmbox/swarm/scout_behaviour.hpp"
#include "swarmbox/swarm/search_pattern.hpp"
#include "swarmbox/swarm/victim_perception.hpp"
