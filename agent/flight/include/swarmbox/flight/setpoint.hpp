// The setpoint interface the layers above (flocking, mission, the agent's built-in plan) drive,
// and the flight modes and events the flight controller reports back.
//
//   controller.Command(Setpoint::Takeoff(5.0));            // climb 5 m above where it stands
//   controller.Command(Setpoint::Position({10, 0, 5}, 0)); // fly there, nose east
//   controller.Command(Setpoint::Velocity({2, 0, 0}, 0));  // 2 m/s east, holding altitude rate 0
//   controller.Command(Setpoint::Hold());                  // stop and hold where it is
//   controller.Command(Setpoint::Land());
//   TrajectoryTarget t;                                    // PX4 TrajectorySetpoint: NaN = unset
//   t.pos_m = Vec3(10, 0, kUnset); t.vel_m_s = Vec3(kUnset, kUnset, 0.5);
//   controller.Command(Setpoint::Trajectory(t));           // x, y to 10, 0; climb at 0.5 m/s
//   FlightEvent e; while (controller.PopEvent(&e)) log(e);   // takeoff, hover, arrived, landed...
//
// The trajectory kind is PX4's TrajectorySetpoint as the offboard interface (agent/brain) passes
// it, flown as PX4's PositionControl flies it, per world axis (x, y, z):
//   position finite      -> position P, the velocity (NaN: 0) and acceleration (NaN: 0) feed
//                           forward;
//   else velocity finite -> velocity PID, the acceleration (NaN: 0) feeds forward;
//   else accel. finite   -> that acceleration alone (no velocity loop on the axis, its integral
//                           frozen), e.g. z: the thrust for that vertical acceleration;
//   all three NaN        -> the axis holds where it stops: position P on the point where braking
//                           at the acceleration limit from the estimate at the command ends (kept
//                           while later setpoints leave the axis unset).
// Heading: yaw finite -> that heading; else yawspeed finite -> the heading setpoint turns at that
// rate (limited to 1.5 rad/s), also fed forward; both NaN -> the heading setpoint is kept.
// Not smoothed: no reference generator, no input shaper, no `arrived` event (the brain streams
// its own trajectory, as in PX4 offboard). Limits as for the other kinds: the velocity (setpoint,
// feed-forward and the position loop's output) within the airframe's vel_max_xy/up/down
// (control.limits), the tilt and thrust limits of the position controller. Infinite values are
// rejected (NaN is "unset", not an error). Accepted only in the air, as Position and Velocity.
// Setpoint::FromTrajectory picks the smoothed Position/Velocity kind when the target is exactly
// one of those (what a brain's Position()/Velocity() helpers make).
#pragma once

#include <cstdint>
#include <cmath>
#include <limits>
#include <string_view>

#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {

inline constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();

// PX4 TrajectorySetpoint (px4_msgs/msg/TrajectorySetpoint.msg) in world ENU and SI units; kUnset
// (NaN) = unset, per component. Default: everything unset (= hold, keep the heading).
struct TrajectoryTarget {
  Vec3 pos_m = Vec3::Constant(kUnset);      // world ENU [m]
  Vec3 vel_m_s = Vec3::Constant(kUnset);    // world ENU [m/s]
  Vec3 acc_m_s2 = Vec3::Constant(kUnset);   // world ENU [m/s^2], gravity not included
  double yaw_rad = kUnset;                  // heading, ENU (0 = east, counter-clockwise)
  double yawspeed_rad_s = kUnset;           // heading rate, counter-clockwise positive [rad/s]
};

struct Setpoint {
  enum class Kind : std::uint8_t { kTakeoff, kPosition, kVelocity, kHold, kLand, kTrajectory };
  Kind kind = Kind::kHold;
  Vec3 value = Vec3::Zero();  // takeoff: (0, 0, height above the start [m]); position: world ENU
                              // [m]; velocity: world ENU [m/s]; trajectory: unused (zero)
  double yaw_rad = 0.0;       // heading, ENU (0 = east); NaN keeps the current heading;
                              // trajectory: unused (NaN), the target's yaw/yawspeed count
  TrajectoryTarget trajectory{};  // trajectory kind only

  static Setpoint Takeoff(double height_m) { return {Kind::kTakeoff, Vec3(0.0, 0.0, height_m), std::nan("")}; }
  static Setpoint Position(const Vec3& pos_m, double yaw_rad) { return {Kind::kPosition, pos_m, yaw_rad}; }
  static Setpoint Velocity(const Vec3& vel_m_s, double yaw_rad) { return {Kind::kVelocity, vel_m_s, yaw_rad}; }
  static Setpoint Hold() { return {Kind::kHold, Vec3::Zero(), std::nan("")}; }
  static Setpoint Land() { return {Kind::kLand, Vec3::Zero(), std::nan("")}; }
  static Setpoint Trajectory(const TrajectoryTarget& target) {
    return {Kind::kTrajectory, Vec3::Zero(), std::nan(""), target};
  }
  // The kind the flight stack flies best for a TrajectorySetpoint: Position (smoothed, `arrived`)
  // when exactly the three positions are set (yaw optional), Velocity when exactly the three
  // velocities are (yaw optional), otherwise Trajectory.
  static Setpoint FromTrajectory(const TrajectoryTarget& target);
};

enum class FlightMode : std::uint8_t {
  kInit,      // estimator aligning; motors off
  kIdle,      // on the ground, disarmed, ready
  kTakeoff,   // climbing to the take-off height
  kHold,      // holding a position
  kPosition,  // flying to a position
  kVelocity,  // following a velocity
  kTrajectory,  // following a trajectory setpoint stream (PX4 TrajectorySetpoint, offboard)
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
  kRejected,      // a setpoint that the current mode cannot take (e.g. position while landed,
                  // anything but take-off on the ground), or with infinite values
};
std::string_view FlightEventName(FlightEventKind kind);

struct FlightEvent {
  FlightEventKind kind = FlightEventKind::kReady;
  double t_s = 0.0;
  FlightMode mode = FlightMode::kInit;  // mode after the event
  Vec3 pos_m = Vec3::Zero();            // estimated position then
};

}  // namespace swarmbox::flight
