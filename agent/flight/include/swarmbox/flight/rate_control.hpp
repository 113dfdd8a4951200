// Body-rate PID with anti-windup: the innermost loop of the cascade (PX4 src/lib/rate_control).
//
//   RateControl rc;
//   rc.SetGains(gains);
//   Vec3 torque_norm = rc.Update(rate_rad_s, rate_sp_rad_s, ang_accel_rad_s2, dt_s, landed);
//   ... mixer ...
//   rc.SetSaturation(mixer_output.sat_positive, mixer_output.sat_negative);
//
// Output: body torque normalised to the airframe's torque authority, roughly [-1, 1] per axis
// (the mixer scales it to N m); this keeps PX4's gain values meaningful. Pure, no allocation.
#pragma once

#include <array>

#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {

struct RateGains {
  Vec3 p = Vec3(0.15, 0.15, 0.2);         // [norm torque / (rad/s)]
  Vec3 i = Vec3(0.2, 0.2, 0.1);           // [norm torque / rad]
  Vec3 d = Vec3(0.003, 0.003, 0.0);       // [norm torque / (rad/s^2)]
  Vec3 ff = Vec3::Zero();                 // [norm torque / (rad/s)]
  Vec3 integrator_limit = Vec3(0.3, 0.3, 0.3);  // |integral| bound [norm torque]
};

class RateControl {
 public:
  void SetGains(const RateGains& gains) { gains_ = gains; }
  const RateGains& gains() const { return gains_; }

  // rate, rate_sp: body FLU [rad/s]; angular_accel: measured derivative of rate [rad/s^2] (for
  // the D term on measurement, no derivative kick). No integration while `landed`.
  Vec3 Update(const Vec3& rate, const Vec3& rate_sp, const Vec3& angular_accel, double dt_s,
              bool landed);

  // Mixer feedback for anti-windup: an axis saturated in one direction stops integrating in it.
  void SetSaturation(const std::array<bool, 3>& sat_positive, const std::array<bool, 3>& sat_negative) {
    sat_positive_ = sat_positive;
    sat_negative_ = sat_negative;
  }
  void ResetIntegral() { integral_.setZero(); }
  const Vec3& integral() const { return integral_; }

 private:
  RateGains gains_;
  Vec3 integral_ = Vec3::Zero();
  std::array<bool, 3> sat_positive_{};
  std::array<bool, 3> sat_negative_{};
};

}  // namespace swarmbox::flight
