// Closed-loop test rig: a FlightController flying a drone of the in-process physics World
// (ODE, seeded sensor noise), lockstep as the server does it: read the sample, answer it, step.
// Used by closed_loop_test.cpp and by the `flight` benchmark suite.
//
// The receiver's frame. A real GPS receiver's error wanders (metres over minutes, ~0.25 m a
// minute from multipath; physics_server/src/sensor_models.hpp), and over seconds no GPS-based
// navigation can tell that wander from motion. The rig therefore also measures positions in the
// receiver's frame: nav_pos() = truth + (the receiver's horizontal correlated error now - at the
// reference mark, the take-off), i.e. where the drone is as its GPS sees it, which is what the
// flight stack can be held to. Heights stay absolute: they come from the barometer. The error comes from a twin of the drone's GpsErrorModel (same seed
// derivation as the World's, advanced on the same fixes); every fix is checked against the
// World's to 1e-9 m, so a change in the World's seeding fails loudly instead of measuring wrong.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/flight/flight_controller.hpp"
#include "swarmbox/physics/world.hpp"
#include "sensor_models.hpp"  // physics_server/src: GpsErrorModel

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
  // The airframe's GPS receiver as its YAML says (standalone for all of trials/airframes), or
  // switched to an RTK-fixed ZED-F9P this far from its base (physics::SetRtkFix).
  physics::GpsFix gps_fix = physics::GpsFix::kStandalone;
  double rtk_baseline_km = 1.0;
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
  // Truth shifted by the receiver's correlated error since MarkGpsReference() (see above).
  Vec3 nav_pos() const;
  // The receiver's correlated (slow + wander) error at the last fix, world ENU [m].
  Vec3 gps_error() const;
  void MarkGpsReference() { gps_ref_ = gps_error(); }
  // False once a fix disagreed with the twin error model (the metrics would be wrong).
  bool gps_twin_ok() const { return twin_ok_; }
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
  // GPS error twin and the truth history it needs for the fix latency.
  void RecordTruthAndCheckGps();
  std::unique_ptr<physics::GpsErrorModel> twin_;
  physics::GpsErrorModel::Split split_{};
  std::int64_t last_fix_ns_ = -1;
  static constexpr std::size_t kHist = 256;
  std::array<std::int64_t, kHist> hist_t_{};
  std::array<physics::Vec3, kHist> hist_p_{};
  std::size_t hist_n_ = 0;
  Vec3 gps_ref_ = Vec3::Zero();
  bool twin_ok_ = true;
};

}  // namespace swarmbox::flight::testing
