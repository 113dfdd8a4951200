// The setpoint interface the layers above (flocking, mission, the agent's built-in plan) drive,
// and the flight modes and events the flight controller reports back.
//
//   controller.Command(Setpoint::Takeoff(5.0));            // climb 5 m above where it stands
//   controller.Command(Setpoint::Position({10, 0, 5}, 0)); // fly there, nose east
//   controller.Command(Setpoint::Velocity({2, 0, 0}, 0));  // 2 m/s east, holding altitude rate 0
//   controller.Command(Setpoint::Hold());                  // stop and hold where it is
//   controller.Command(Setpoint::Land());
//   FlightEvent e; while (controller.PopEvent(&e)) log(e);   // takeoff, hover, arrived, landed...
#pragma once

#include <cstdint>
#include <cmath>
#include <string_view>

#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {

struct Setpoint {
  enum class Kind : std::uint8_t { kTakeoff, kPosition, kVelocity, kHold, kLand };
  Kind kind = Kind::kHold;
  Vec3 value = Vec3::Zero();  // takeoff: (0, 0, height above the start [m]); position: world ENU
                              // [m]; velocity: world ENU [m/s]
  double yaw_rad = 0.0;       // heading, ENU (0 = east); NaN keeps the current heading

  static Setpoint Takeoff(double height_m) { return {Kind::kTakeoff, Vec3(0.0, 0.0, height_m), std::nan("")}; }
  static Setpoint Position(const Vec3& pos_m, double yaw_rad) { return {Kind::kPosition, pos_m, yaw_rad}; }
  static Setpoint Velocity(const Vec3& vel_mps, double yaw_rad) { return {Kind::kVelocity, vel_mps, yaw_rad}; }
  static Setpoint Hold() { return {Kind::kHold, Vec3::Zero(), std::nan("")}; }
  static Setpoint Land() { return {Kind::kLand, Vec3::Zero(), std::nan("")}; }
};

enum class FlightMode : std::uint8_t {
  kInit,      // estimator aligning; motors off
  kIdle,      // on the ground, disarmed, ready
  kTakeoff,   // climbing to the take-off height
  kHold,      // holding a position
  kPosition,  // flying to a position
  kVelocity,  // following a velocity
  kLand,      // descending to touch down
  kLanded,    // touched down, motors off (a new take-off is allowed)
};
std::string_view FlightModeName(FlightMode mode);

enum class FlightEventKind : std::uint8_t {
  kReady,         // estimator aligned: t, position
  kTakeoff,       // take-off started
  kHover,         // take-off height reached, holding
  kArrived,       // a position setpoint reached (within 0.3 m, slow)
  kLanding,       // landing started
  kLanded,        // touched down, motors off
  kModeChange,    // any mode change (mode = the new one)
  kGpsLost,       // no GPS fix for the estimator's timeout: dead reckoning
  kGpsRecovered,  // GPS back
  kRejected,      // a setpoint that the current mode cannot take (e.g. position while landed)
};
std::string_view FlightEventName(FlightEventKind kind);

struct FlightEvent {
  FlightEventKind kind = FlightEventKind::kReady;
  double t_s = 0.0;
  FlightMode mode = FlightMode::kInit;  // mode after the event
  Vec3 pos_m = Vec3::Zero();            // estimated position then
};

}  // namespace swarmbox::flight
