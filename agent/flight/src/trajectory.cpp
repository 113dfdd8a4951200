#include "swarmbox/flight/trajectory.hpp"

#include <algorithm>
#include <cmath>

namespace swarmbox::flight {

void Trajectory::Reset(const Vec3& pos_m, const Vec3& vel_m_s) {
  ref_.pos_m = pos_m;
  ref_.vel_m_s = LimitVelocity(vel_m_s);
  ref_.acc_m_s2.setZero();
  target_ = pos_m;
  velocity_mode_ = false;
}

void Trajectory::SetPositionTarget(const Vec3& pos_m) {
  target_ = pos_m;
  velocity_mode_ = false;
}

void Trajectory::SetVelocityTarget(const Vec3& vel_m_s) {
  target_ = LimitVelocity(vel_m_s);
  velocity_mode_ = true;
}

Vec3 Trajectory::LimitVelocity(const Vec3& v) const {
  double scale = 1.0;
  const double vxy = v.head<2>().norm();
  if (vxy > limits_.vel_max_xy_m_s) scale = std::min(scale, limits_.vel_max_xy_m_s / vxy);
  if (v.z() > limits_.vel_max_up_m_s) scale = std::min(scale, limits_.vel_max_up_m_s / v.z());
  if (v.z() < -limits_.vel_max_down_m_s) scale = std::min(scale, -limits_.vel_max_down_m_s / v.z());
  return v * scale;
}

Vec3 Trajectory::ApproachVelocity() const {
  const Vec3 d = target_ - ref_.pos_m;
  const double dist = d.norm();
  if (dist < 1e-9) return Vec3::Zero();
  // Braking acceleration along the way: the smaller of the axis limits it projects onto.
  const Vec3 dir = d / dist;
  const double a_h = limits_.acc_max_xy_m_s2, a_v = limits_.acc_max_z_m_s2;
  const double dxy = dir.head<2>().norm(), dz = std::abs(dir.z());
  double a_along = 1e9;
  if (dxy > 1e-9) a_along = std::min(a_along, a_h / dxy);
  if (dz > 1e-9) a_along = std::min(a_along, a_v / dz);
  // Brake a little early (0.8 a) so discretisation never overshoots the target.
  const double speed = std::min(std::sqrt(2.0 * 0.8 * a_along * dist), limits_.approach_gain * dist);
  return LimitVelocity(dir * speed);
}

TrajectoryPoint Trajectory::Step(double dt_s) {
  if (!(dt_s > 0.0)) return ref_;
  const Vec3 v_des = velocity_mode_ ? target_ : ApproachVelocity();
  // Velocity change limited per axis group (horizontal vector norm, vertical).
  Vec3 dv = v_des - ref_.vel_m_s;
  const double max_dxy = limits_.acc_max_xy_m_s2 * dt_s;
  const double max_dz = limits_.acc_max_z_m_s2 * dt_s;
  const double nxy = dv.head<2>().norm();
  if (nxy > max_dxy) dv.head<2>() *= max_dxy / nxy;
  dv.z() = std::clamp(dv.z(), -max_dz, max_dz);
  const Vec3 v_new = ref_.vel_m_s + dv;
  ref_.pos_m += 0.5 * (ref_.vel_m_s + v_new) * dt_s;
  ref_.acc_m_s2 = dv / dt_s;
  ref_.vel_m_s = v_new;
  if (!velocity_mode_ && (target_ - ref_.pos_m).norm() < 1e-4 && ref_.vel_m_s.norm() < 1e-3) {
    ref_.pos_m = target_;  // snap the last tenth of a millimetre
    ref_.vel_m_s.setZero();
    ref_.acc_m_s2.setZero();
  }
  return ref_;
}

bool Trajectory::Settled(double tol_m) const {
  return !velocity_mode_ && (target_ - ref_.pos_m).norm() < tol_m && ref_.vel_m_s.norm() < 0.05;
}

}  // namespace swarmbox::flight
