#include "swarmbox/flight/position_control.hpp"

#include <algorithm>
#include <cmath>

namespace swarmbox::flight {
namespace {

bool Finite(const Vec3& v) { return v.allFinite(); }

}  // namespace

Quat AttitudeFromThrustAndYaw(const Vec3& body_z_in, double yaw_rad) {
  Vec3 body_z = body_z_in.norm() > 1e-9 ? body_z_in.normalized() : Vec3::UnitZ();
  const Vec3 y_c(-std::sin(yaw_rad), std::cos(yaw_rad), 0.0);  // heading's left vector, level
  Vec3 body_x = y_c.cross(body_z);
  if (body_z.z() < 0.0) body_x = -body_x;  // upside-down: keep the nose on the heading
  if (body_x.norm() < 1e-6) {
    body_x = Vec3::UnitX();  // thrust horizontal and along the left vector: any x will do
  }
  body_x.normalize();
  const Vec3 body_y = body_z.cross(body_x);
  Eigen::Matrix3d r;
  r.col(0) = body_x;
  r.col(1) = body_y;
  r.col(2) = body_z;
  return Quat(r).normalized();
}

PositionOutput PositionControl::Update(const StateEstimate& state, const PositionSetpoint& sp,
                                       double mass_kg, double dt_s) {
  PositionOutput out;
  if (!Finite(state.pos_m) || !Finite(state.vel_mps) || !Finite(sp.pos_m) || !Finite(sp.vel_mps) ||
      !Finite(sp.acc_mps2) || !std::isfinite(sp.yaw_rad) || !(mass_kg > 0.0)) {
    return out;
  }
  const PositionParams& p = params_;

  // Position P -> velocity setpoint, with the velocity limits.
  Vec3 vel_sp = sp.vel_mps;
  if (sp.pos_xy) vel_sp.head<2>() += p.xy_p * (sp.pos_m - state.pos_m).head<2>();
  if (sp.pos_z) vel_sp.z() += p.z_p * (sp.pos_m.z() - state.pos_m.z());
  const double vxy = vel_sp.head<2>().norm();
  if (vxy > p.vel_max_xy_mps) vel_sp.head<2>() *= p.vel_max_xy_mps / vxy;
  vel_sp.z() = std::clamp(vel_sp.z(), -p.vel_max_down_mps, p.vel_max_up_mps);

  // Velocity PID -> acceleration setpoint (D on the measured acceleration).
  const Vec3 vel_err = vel_sp - state.vel_mps;
  Vec3 acc_sp = p.vel_p.cwiseProduct(vel_err) + integral_ - p.vel_d.cwiseProduct(state.accel_mps2) +
                sp.acc_mps2;

  // Thrust: vertical first (altitude has priority), then horizontal within the tilt and the
  // remaining thrust margin.
  const double f_min = p.thrust_min_n;
  const double f_max = p.thrust_max_n;
  const double fz_raw = mass_kg * (acc_sp.z() + kGravity_mps2);
  const double fz = std::clamp(fz_raw, std::max(f_min, 1e-3), f_max);
  Vec3 f_xy_raw(mass_kg * acc_sp.x(), mass_kg * acc_sp.y(), 0.0);
  double f_xy_max = fz * std::tan(std::min(p.tilt_max_rad, 89.0 * kPi / 180.0));
  f_xy_max = std::min(f_xy_max, std::sqrt(std::max(0.0, f_max * f_max - fz * fz)));
  Vec3 f_xy = f_xy_raw;
  if (f_xy.norm() > f_xy_max) f_xy *= f_xy_max / f_xy.norm();
  const Vec3 thrust(f_xy.x(), f_xy.y(), fz);

  // Anti-windup. Vertical: stop integrating into a saturated thrust. Horizontal: PX4's scheme,
  // feed back the part of the acceleration the limits took away.
  if (dt_s > 0.0) {
    const double ez = vel_err.z();
    const bool sat_hi = fz_raw >= f_max && ez > 0.0;
    const bool sat_lo = fz_raw <= f_min && ez < 0.0;
    if (!sat_hi && !sat_lo) integral_.z() += p.vel_i.z() * ez * dt_s;
    const Vec3 acc_xy_lim = f_xy / mass_kg;
    const Vec3 acc_xy_raw = f_xy_raw / mass_kg;
    for (int a = 0; a < 2; ++a) {
      const double arw_gain = p.vel_p[a] > 0.0 ? 2.0 / p.vel_p[a] : 0.0;
      const double e = vel_err[a] - arw_gain * (acc_xy_raw[a] - acc_xy_lim[a]);
      integral_[a] += p.vel_i[a] * e * dt_s;
    }
    for (int a = 0; a < 3; ++a) {
      integral_[a] = std::clamp(integral_[a], -p.integral_max_mps2, p.integral_max_mps2);
    }
  }

  out.valid = true;
  out.thrust_world_n = thrust;
  out.thrust_n = thrust.norm();
  out.att_sp = AttitudeFromThrustAndYaw(thrust, sp.yaw_rad);
  out.vel_sp_mps = vel_sp;
  out.acc_sp_mps2 = Vec3(f_xy.x() / mass_kg, f_xy.y() / mass_kg, fz / mass_kg - kGravity_mps2);
  return out;
}

}  // namespace swarmbox::flight
