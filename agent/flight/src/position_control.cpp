#include "swarmbox/flight/position_control.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace swarmbox::flight {
namespace {

bool Finite(const Vec3& v) { return v.allFinite(); }

bool AxisIs(const PositionSetpoint& sp, int a, AxisControl c) {
  return sp.axes[static_cast<std::size_t>(a)] == c;
}

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

// Update follows PX4's PositionControl::update: position control (velocity setpoint), velocity
// control (acceleration setpoint), thrust within the limits, then the integrator's anti-windup.
PositionOutput PositionControl::Update(const StateEstimate& state, const PositionSetpoint& sp,
                                       double mass_kg, double dt_s) {
  PositionOutput out;
  if (!Finite(state.pos_m) || !Finite(state.vel_m_s) || !Finite(sp.pos_m) || !Finite(sp.vel_m_s) ||
      !Finite(sp.acc_m_s2) || !std::isfinite(sp.yaw_rad) || !(mass_kg > 0.0)) {
    return out;
  }
  Vec3 vel_sp = VelocitySetpoint(state, sp);
  Vec3 vel_err;
  const Vec3 acc_sp = AccelerationSetpoint(state, sp, &vel_sp, &vel_err);
  const ThrustSplit f = LimitThrust(acc_sp, mass_kg);
  if (dt_s > 0.0) UpdateIntegral(sp, f, vel_err, mass_kg, dt_s);
  const Vec3 thrust(f.xy.x(), f.xy.y(), f.z);
  out.valid = true;
  out.thrust_world_n = thrust;
  out.thrust_n = thrust.norm();
  out.att_sp = AttitudeFromThrustAndYaw(thrust, sp.yaw_rad);
  out.vel_sp_m_s = vel_sp;
  out.acc_sp_m_s2 = Vec3(f.xy.x() / mass_kg, f.xy.y() / mass_kg, f.z / mass_kg - kGravity_m_s2);
  return out;
}

Vec3 PositionControl::VelocitySetpoint(const StateEstimate& state, const PositionSetpoint& sp) const {
  const PositionParams& p = params_;
  // Position P -> velocity setpoint, with the velocity limits. Acceleration-only axes have none.
  Vec3 vel_sp = sp.vel_m_s;
  for (int a = 0; a < 3; ++a) {
    if (AxisIs(sp, a, AxisControl::kPosition)) {
      vel_sp[a] += (a < 2 ? p.xy_p : p.z_p) * (sp.pos_m[a] - state.pos_m[a]);
    } else if (AxisIs(sp, a, AxisControl::kAcceleration)) {
      vel_sp[a] = 0.0;
    }
  }
  const double vel_max_xy = std::min(p.vel_max_xy_m_s, sp.vel_cap_xy_m_s);
  const double vxy = vel_sp.head<2>().norm();
  if (vxy > vel_max_xy) vel_sp.head<2>() *= vel_max_xy / vxy;
  vel_sp.z() = std::clamp(vel_sp.z(), -std::min(p.vel_max_down_m_s, sp.vel_cap_down_m_s),
                          std::min(p.vel_max_up_m_s, sp.vel_cap_up_m_s));
  return vel_sp;
}

Vec3 PositionControl::AccelerationSetpoint(const StateEstimate& state, const PositionSetpoint& sp,
                                           Vec3* vel_sp, Vec3* vel_err) const {
  const PositionParams& p = params_;
  // Velocity PID -> acceleration setpoint (D on the measured acceleration); acceleration-only
  // axes take the feed-forward alone (PX4: a NaN velocity setpoint leaves the axis to it).
  *vel_err = *vel_sp - state.vel_m_s;
  Vec3 acc_sp = p.vel_p.cwiseProduct(*vel_err) + integral_ - p.vel_d.cwiseProduct(state.accel_m_s2) +
                sp.acc_m_s2;
  for (int a = 0; a < 3; ++a) {
    if (AxisIs(sp, a, AxisControl::kAcceleration)) {
      (*vel_err)[a] = 0.0;
      (*vel_sp)[a] = std::numeric_limits<double>::quiet_NaN();
      acc_sp[a] = sp.acc_m_s2[a];
    }
  }
  return acc_sp;
}

PositionControl::ThrustSplit PositionControl::LimitThrust(const Vec3& acc_sp, double mass_kg) const {
  const PositionParams& p = params_;
  // Thrust: vertical first (altitude has priority), then horizontal within the tilt and the
  // remaining thrust margin.
  const double f_min = p.thrust_min_n;
  const double f_max = p.thrust_max_n;
  ThrustSplit f;
  f.z_raw = mass_kg * (acc_sp.z() + kGravity_m_s2);
  f.z = std::clamp(f.z_raw, std::max(f_min, 1e-3), f_max);
  f.xy_raw = Vec3(mass_kg * acc_sp.x(), mass_kg * acc_sp.y(), 0.0);
  double f_xy_max = f.z * std::tan(std::min(p.tilt_max_rad, 89.0 * kPi / 180.0));
  f_xy_max = std::min(f_xy_max, std::sqrt(std::max(0.0, f_max * f_max - f.z * f.z)));
  f.xy = f.xy_raw;
  if (f.xy.norm() > f_xy_max) f.xy *= f_xy_max / f.xy.norm();
  return f;
}

void PositionControl::UpdateIntegral(const PositionSetpoint& sp, const ThrustSplit& f, const Vec3& vel_err,
                                     double mass_kg, double dt_s) {
  const PositionParams& p = params_;
  // Anti-windup. Vertical: stop integrating into a saturated thrust. Horizontal: PX4's scheme,
  // feed back the part of the acceleration the limits took away.
  const double ez = vel_err.z();
  const bool sat_hi = f.z_raw >= p.thrust_max_n && ez > 0.0;
  const bool sat_lo = f.z_raw <= p.thrust_min_n && ez < 0.0;
  if (!sat_hi && !sat_lo && !AxisIs(sp, 2, AxisControl::kAcceleration)) integral_.z() += p.vel_i.z() * ez * dt_s;
  const Vec3 acc_xy_lim = f.xy / mass_kg;
  const Vec3 acc_xy_raw = f.xy_raw / mass_kg;
  for (int a = 0; a < 2; ++a) {
    if (AxisIs(sp, a, AxisControl::kAcceleration)) continue;  // frozen
    const double arw_gain = p.vel_p[a] > 0.0 ? 2.0 / p.vel_p[a] : 0.0;
    const double e = vel_err[a] - arw_gain * (acc_xy_raw[a] - acc_xy_lim[a]);
    integral_[a] += p.vel_i[a] * e * dt_s;
  }
  for (int a = 0; a < 3; ++a) {
    integral_[a] = std::clamp(integral_[a], -p.integral_max_m_s2, p.integral_max_m_s2);
  }
}

}  // namespace swarmbox::flight
