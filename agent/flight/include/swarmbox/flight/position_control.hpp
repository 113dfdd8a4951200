// Position P -> velocity PID -> thrust vector with tilt limit -> attitude setpoint
// (the structure of PX4 mc_pos_control/PositionControl, in ENU and SI units).
//
// Gains are in acceleration units ([m/s^2 per m/s], as PX4's MPC_*_VEL_*_ACC), so the loop shape
// does not change with the vehicle's mass; the mass (from the hover-thrust estimate) only turns the
// acceleration into newtons.
//
// Per axis as PX4's PositionControl with NaN setpoints: position P + velocity feed-forward,
// velocity PID + acceleration feed-forward, or acceleration alone (PositionSetpoint::axes).
//
//   PositionControl pc;  pc.SetParams(params);
//   PositionOutput out = pc.Update(state, setpoint, mass_kg, dt_s);
//   if (out.valid) { attitude control with out.att_sp; mixer with out.thrust_n; }
#pragma once

#include <array>
#include <cstdint>
#include <limits>

#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {

struct PositionParams {
  double xy_p = 0.95;            // [1/s]
  double z_p = 1.0;              // [1/s]
  Vec3 vel_p = Vec3(1.8, 1.8, 4.0);   // [(m/s^2)/(m/s)]
  Vec3 vel_i = Vec3(0.4, 0.4, 2.0);   // [(m/s^2)/m]
  Vec3 vel_d = Vec3(0.2, 0.2, 0.0);   // [(m/s^2)/(m/s^2)]
  double vel_max_xy_m_s = 5.0;
  double vel_max_up_m_s = 3.0;
  double vel_max_down_m_s = 1.5;
  double tilt_max_rad = 45.0 * kPi / 180.0;
  double thrust_min_n = 0.0;     // collective thrust bounds [N] (from the airframe)
  double thrust_max_n = 1.0;
  double integral_max_m_s2 = 4.0;  // |velocity integral| per axis [m/s^2]
};

// How one world axis is controlled (PX4 PositionControl with NaN setpoints).
enum class AxisControl : std::uint8_t {
  kPosition,      // position P; vel_m_s and acc_m_s2 feed forward
  kVelocity,      // vel_m_s tracked by the velocity PID; acc_m_s2 feeds forward
  kAcceleration,  // acc_m_s2 alone: no velocity loop on this axis, its integral frozen
};

// What the layers above want, per world axis (x, y, z). Feed-forwards are world ENU.
struct PositionSetpoint {
  std::array<AxisControl, 3> axes{AxisControl::kPosition, AxisControl::kPosition, AxisControl::kPosition};
  Vec3 pos_m = Vec3::Zero();       // used on kPosition axes
  Vec3 vel_m_s = Vec3::Zero();     // feed-forward (kPosition) or setpoint (kVelocity)
  Vec3 acc_m_s2 = Vec3::Zero();    // feed-forward, or the setpoint (kAcceleration)
  double yaw_rad = 0.0;
  double yawspeed_rad_s = 0.0;     // feed-forward
  // Velocity limits of this setpoint when tighter than the params' (the trajectory kind flies at
  // the airframe's limits, with no reference to chase) [m/s]; infinity: the params' alone.
  double vel_cap_xy_m_s = std::numeric_limits<double>::infinity();
  double vel_cap_up_m_s = std::numeric_limits<double>::infinity();
  double vel_cap_down_m_s = std::numeric_limits<double>::infinity();
};

struct PositionOutput {
  bool valid = false;               // false: non-finite input, nothing to fly
  Vec3 thrust_world_n = Vec3::Zero();
  double thrust_n = 0.0;            // collective thrust along body z [N]
  Quat att_sp = Quat::Identity();   // body FLU -> world ENU
  Vec3 vel_sp_m_s = Vec3::Zero();   // after limits, for logs and tests; NaN on kAcceleration axes
  Vec3 acc_sp_m_s2 = Vec3::Zero();  // after limits
};

class PositionControl {
 public:
  void SetParams(const PositionParams& params) { params_ = params; }
  const PositionParams& params() const { return params_; }
  PositionOutput Update(const StateEstimate& state, const PositionSetpoint& sp, double mass_kg,
                        double dt_s);
  void ResetIntegral() { integral_.setZero(); }
  const Vec3& integral() const { return integral_; }

 private:
  // The thrust before and after its limits [N] (world frame; xy with z = 0).
  struct ThrustSplit {
    double z_raw = 0.0;
    double z = 0.0;
    Vec3 xy_raw = Vec3::Zero();
    Vec3 xy = Vec3::Zero();
  };
  // Update's steps (PX4's _positionControl, _velocityControl, thrust limits, anti-windup).
  Vec3 VelocitySetpoint(const StateEstimate& state, const PositionSetpoint& sp) const;
  // Acceleration-only axes: *vel_sp becomes NaN and *vel_err 0 there.
  Vec3 AccelerationSetpoint(const StateEstimate& state, const PositionSetpoint& sp, Vec3* vel_sp,
                            Vec3* vel_err) const;
  ThrustSplit LimitThrust(const Vec3& acc_sp, double mass_kg) const;
  void UpdateIntegral(const PositionSetpoint& sp, const ThrustSplit& f, const Vec3& vel_err, double mass_kg,
                      double dt_s);

  PositionParams params_;
  Vec3 integral_ = Vec3::Zero();  // [m/s^2]
};

// Attitude whose body z is `body_z` (world, normalised inside) and whose heading is `yaw_rad`
// (PX4 bodyzToAttitude).
Quat AttitudeFromThrustAndYaw(const Vec3& body_z, double yaw_rad);

}  // namespace swarmbox::flight
