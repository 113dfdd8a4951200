#include "swarmbox/flight/swing_damping.hpp"

#include <algorithm>
#include <cmath>

namespace swarmbox::flight {

double LoadScaledDampingGain(double gain, double payload_mass_kg, double drone_mass_kg, double full_ratio) {
  if (!(full_ratio > 0.0)) return gain;
  if (!(drone_mass_kg > 0.0) || !(payload_mass_kg > 0.0)) return 0.0;
  return gain * std::min(1.0, payload_mass_kg / (full_ratio * drone_mass_kg));
}

void InputShaper::Configure(double period_s, double damping_ratio, double dt_s) {
  buffer_.clear();
  if (!(period_s > 0.0) || !(dt_s > 0.0)) return;
  const double z = std::clamp(damping_ratio, 0.0, 0.9);
  const double k = std::exp(-z * kPi / std::sqrt(1.0 - z * z));
  const double norm = (1.0 + k) * (1.0 + k);
  a0_ = 1.0 / norm;
  a1_ = 2.0 * k / norm;
  a2_ = k * k / norm;
  full_ = static_cast<std::size_t>(std::lround(period_s / dt_s));
  half_ = full_ / 2;
  delay_s_ = static_cast<double>(full_) * dt_s;
  buffer_.assign(full_ + 1, TrajectoryPoint{});
  head_ = 0;
}

void InputShaper::Reset(const TrajectoryPoint& p) {
  std::fill(buffer_.begin(), buffer_.end(), p);
}

TrajectoryPoint InputShaper::Shape(const TrajectoryPoint& raw) {
  if (buffer_.empty()) return raw;
  const std::size_t n = buffer_.size();
  head_ = (head_ + 1) % n;
  buffer_[head_] = raw;
  const TrajectoryPoint& p1 = buffer_[(head_ + n - half_) % n];
  const TrajectoryPoint& p2 = buffer_[(head_ + n - full_) % n];
  TrajectoryPoint out;
  out.pos_m = a0_ * raw.pos_m + a1_ * p1.pos_m + a2_ * p2.pos_m;
  out.vel_m_s = a0_ * raw.vel_m_s + a1_ * p1.vel_m_s + a2_ * p2.vel_m_s;
  out.acc_m_s2 = a0_ * raw.acc_m_s2 + a1_ * p1.acc_m_s2 + a2_ * p2.acc_m_s2;
  return out;
}

void SwingObserver::Configure(double sling_length_m, double drone_mass_kg) {
  length_m_ = sling_length_m;
  drone_mass_kg_ = drone_mass_kg;
  Reset();
}

void SwingObserver::Reset() {
  s_.setZero();
  s_dot_.setZero();
  s_meas_.setZero();
  offset_.setZero();
  active_ = false;
}

void SwingObserver::Update(const Vec3& f_body, const Quat& att, const Vec3& acc_world,
                           double payload_mass_kg, double dt_s) {
  if (!configured() || !(dt_s > 0.0)) return;
  // Need a load that pulls meaningfully (a slack or absent sling has nothing to observe).
  if (!(payload_mass_kg > 0.05 * drone_mass_kg_)) {
    Reset();
    return;
  }
  // Cable direction in the body from the part of the specific force perpendicular to body z:
  // m_d f_xy = T_c u_xy with tension T_c ~ m_p (g + a_z) (quasi-static).
  const double tension_n = payload_mass_kg * std::max(2.0, kGravity_m_s2 + acc_world.z());
  Vec3 u_b(drone_mass_kg_ * f_body.x() / tension_n, drone_mass_kg_ * f_body.y() / tension_n, 0.0);
  const double h2 = u_b.head<2>().squaredNorm();
  if (h2 > 0.64) u_b.head<2>() *= std::sqrt(0.64 / h2);  // clamp at ~53 deg from body -z
  u_b.z() = -std::sqrt(1.0 - u_b.head<2>().squaredNorm());
  const Vec3 u_w = att * u_b;  // hook -> payload, world
  s_meas_ = Vec3(u_w.x(), u_w.y(), 0.0);
  if (!active_) {
    s_ = s_meas_;
    s_dot_.setZero();
    offset_.setZero();
    active_ = true;
    return;
  }
  // Pendulum observer, per horizontal axis, driven by the hook's (the drone's) acceleration.
  // Gains put the observer poles near 2-3x the pendulum frequency.
  const double w2 = kGravity_m_s2 / length_m_;
  const double l1 = 3.0 * std::sqrt(w2);
  const double l2 = 3.0 * w2;
  // A slow offset state takes what the pendulum model cannot explain (a steady lean of the sling
  // from wind on the payload or a steady acceleration): only the swinging part is damped.
  const double l3 = 1.0;  // [1/s], well below the swing frequency
  for (int a = 0; a < 2; ++a) {
    const double e = s_meas_[a] - s_[a] - offset_[a];
    const double s_ddot = -w2 * s_[a] - acc_world[a] / length_m_ + l2 * e;
    s_[a] += dt_s * (s_dot_[a] + l1 * e);
    s_dot_[a] += dt_s * s_ddot;
    offset_[a] += dt_s * l3 * e;
  }
}

double SwingObserver::swing_angle_rad() const {
  return std::asin(std::min(1.0, (s_ + offset_).head<2>().norm()));
}

Vec3 SwingObserver::DampingAcceleration(double gain) const {
  if (!active_) return Vec3::Zero();
  const double k = gain * std::sqrt(kGravity_m_s2 * length_m_);
  return Vec3(k * s_dot_.x(), k * s_dot_.y(), 0.0);
}

}  // namespace swarmbox::flight
