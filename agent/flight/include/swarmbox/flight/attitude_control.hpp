// Quaternion attitude P controller (the algorithm of PX4 mc_att_control/AttitudeControl, after
// Brescianini, Hehn and D'Andrea, "Nonlinear quadrocopter attitude control", ETH 2013).
//
// Tilt is corrected first: the setpoint is split into a reduced attitude (body z onto the desired
// thrust direction, the shortest way) and a yaw part weighted by yaw_P / mean(roll_P, pitch_P), so
// a large yaw error never spends the thrust-direction authority that keeps the drone in the air.
//
//   AttitudeControl ac;  ac.SetGains(gains);
//   Vec3 rate_sp_rad_s = ac.Update(q_body_to_world, q_setpoint, yawspeed_ff_rad_s);
#pragma once

#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {

struct AttitudeGains {
  Vec3 p = Vec3(6.5, 6.5, 2.8);            // roll, pitch, yaw [(rad/s) / rad]
  Vec3 rate_max_rad_s = Vec3(220.0, 220.0, 200.0) * (kPi / 180.0);  // body rate limits [rad/s]
};

class AttitudeControl {
 public:
  void SetGains(const AttitudeGains& gains);
  // q: body FLU -> world ENU; q_sp: desired; yawspeed_ff: world z rate feed-forward [rad/s].
  // Returns the body rate setpoint, FLU [rad/s].
  Vec3 Update(const Quat& q, const Quat& q_sp, double yawspeed_ff_rad_s) const;

 private:
  AttitudeGains gains_;
  Vec3 p_eff_ = Vec3(6.5, 6.5, 6.5);
  double yaw_w_ = 0.4;
};

}  // namespace swarmbox::flight
