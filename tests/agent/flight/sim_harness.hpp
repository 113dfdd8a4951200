// Closed-loop test rig: a FlightController flying a drone of the in-process physics World
// (ODE, seeded sensor noise), lockstep as the server does it: read the sample, answer it, step.
// Used by closed_loop_test.cpp and by the `flight` benchmark suite.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/flight/flight_controller.hpp"
#include "swarmbox/physics/world.hpp"

namespace swarmbox::flight::testing {

// trials/ of the source tree (compile definition of the test targets).
std::string TrialsDir();

// Physics sample -> the flight stack's sample (the edge conversion the agent does from the bus).
SensorSample FromPhysics(const physics::SensorSample& s);

struct RigOptions {
  std::string airframe = "x500";     // trials/airframes/<airframe>.yaml
  std::uint64_t seed = 42;
  physics::Vec3 start_m{0, 0, 0};
  physics::WindConfig wind;          // none by default
  std::string payload;               // "" or "stretcher"
  bool payload_attached = false;     // hanging at spawn (needs the drone in the air)
  double initial_throttle = 0.0;
  bool swing_damping = true;
  double payload_mass_hint_kg = 0.0; // what the controller is told it carries
};

class Rig {
 public:
  static Result<std::unique_ptr<Rig>> Create(const RigOptions& options);

  // Steps until `done` (checked after every step) or `max_s` of simulated time; `each` runs after
  // every step (metrics). Returns the simulated time run.
  double Run(double max_s, const std::function<bool()>& done = {},
             const std::function<void()>& each = {});
  // Runs until the controller is in `mode` (or max_s); true if it got there.
  bool RunUntilMode(FlightMode mode, double max_s);

  physics::World& world() { return *world_; }
  FlightController& fc() { return *fc_; }
  physics::DroneTruth truth() const { return world_->Truth(drone_); }
  std::size_t drone() const { return drone_; }
  double t() const { return world_->time_s(); }
  Vec3 true_pos() const;
  std::vector<FlightEvent>& events() { return events_; }
  bool HasEvent(FlightEventKind kind) const;
  bool crashed() const { return crashed_; }

 private:
  std::unique_ptr<physics::World> world_;
  std::unique_ptr<FlightController> fc_;
  std::size_t drone_ = 0;
  std::vector<double> u_;
  std::vector<FlightEvent> events_;
  physics::CollectingEventSink sink_;
  bool crashed_ = false;
};

}  // namespace swarmbox::flight::testing
