#include "swarmbox/flight/attitude_control.hpp"

#include <algorithm>
#include <cmath>

namespace swarmbox::flight {

void AttitudeControl::SetGains(const AttitudeGains& gains) {
  gains_ = gains;
  const double rp = 0.5 * (gains.p.x() + gains.p.y());
  // Yaw weight: how much of the yaw error to take into the setpoint; the yaw axis then uses the
  // roll/pitch gain on the weighted error, which gives yaw_P on the full error for small errors.
  yaw_w_ = rp > 0.0 ? std::clamp(gains.p.z() / rp, 0.0, 1.0) : 0.0;
  p_eff_ = gains.p;
  if (yaw_w_ > 1e-6) p_eff_.z() = gains.p.z() / yaw_w_;
}

Vec3 AttitudeControl::Update(const Quat& q_in, const Quat& q_sp_in, double yawspeed_ff_rad_s) const {
  const Quat q = q_in.normalized();
  Quat qd = q_sp_in.normalized();

  // Reduced attitude: rotate body z onto the desired body z by the shortest rotation (world frame).
  const Vec3 e_z = q * Vec3::UnitZ();
  const Vec3 e_z_d = qd * Vec3::UnitZ();
  Quat qd_red = Quat::FromTwoVectors(e_z, e_z_d);
  if (std::abs(qd_red.x()) > 1.0 - 1e-5 || std::abs(qd_red.y()) > 1.0 - 1e-5) {
    // Body z exactly opposite: the reduced attitude is ill-defined, take the full setpoint.
    qd_red = qd;
  } else {
    qd_red = (qd_red * q).normalized();
  }

  // Mix in a weighted share of the remaining yaw rotation.
  Quat q_mix = qd_red.inverse() * qd;
  if (q_mix.w() < 0.0) q_mix.coeffs() = -q_mix.coeffs();
  const double w = std::clamp(q_mix.w(), -1.0, 1.0);
  const double z = std::clamp(q_mix.z(), -1.0, 1.0);
  const Quat yaw_part(std::cos(yaw_w_ * std::acos(w)), 0.0, 0.0, std::sin(yaw_w_ * std::asin(z)));
  qd = (qd_red * yaw_part).normalized();

  // Error quaternion in the body frame; 2 * vector part ~ rotation vector for small errors.
  Quat qe = q.inverse() * qd;
  if (qe.w() < 0.0) qe.coeffs() = -qe.coeffs();
  const Vec3 eq = 2.0 * qe.vec();

  Vec3 rate_sp = p_eff_.cwiseProduct(eq);
  // Yaw-rate feed-forward is about world z: express it in the body frame.
  rate_sp += q.inverse() * (Vec3::UnitZ() * yawspeed_ff_rad_s);
  for (int a = 0; a < 3; ++a) {
    rate_sp[a] = std::clamp(rate_sp[a], -gains_.rate_max_rad_s[a], gains_.rate_max_rad_s[a]);
  }
  return rate_sp;
}

}  // namespace swarmbox::flight
