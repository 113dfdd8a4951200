#include "swarmbox/flight/estimator.hpp"

#include <algorithm>
#include <cmath>

namespace swarmbox::flight {
namespace {

constexpr int kP = 0;  // state indices of an axis filter
constexpr int kV = 1;
constexpr int kBa = 2;
constexpr int kBb = 3;

Quat ExpMap(const Vec3& w_dt) {
  const double a = w_dt.norm();
  if (a < 1e-9) return Quat(1.0, 0.5 * w_dt.x(), 0.5 * w_dt.y(), 0.5 * w_dt.z()).normalized();
  const Vec3 axis = w_dt / a;
  return Quat(Eigen::AngleAxisd(a, axis));
}

}  // namespace

Estimator::Estimator(const EstimatorParams& params) : params_(params) {
  for (int a = 0; a < 3; ++a) ax_[a].n = (a == 2) ? 4 : 3;
}

void Estimator::InitAttitude(const SensorSample& s) {
  // Tilt from gravity (the drone is assumed still at power-up), heading from the magnetometer.
  const Vec3 up_b = s.accel_mps2.norm() > 1e-3 ? Vec3(s.accel_mps2.normalized()) : Vec3::UnitZ();
  const Quat tilt = Quat::FromTwoVectors(up_b, Vec3::UnitZ());  // body -> level frame
  double yaw = 0.0;
  if (s.mag_fresh && s.mag_body.norm() > 1e-9) {
    const Vec3 m_l = tilt * s.mag_body;  // field in a level frame with the body's heading
    const double ref = std::atan2(params_.mag_field_world.y(), params_.mag_field_world.x());
    const double meas = std::atan2(m_l.y(), m_l.x());
    yaw = WrapPi(ref - meas);
  }
  q_ = (QuatFromYaw(yaw) * tilt).normalized();
  att_init_ = true;
}

void Estimator::UpdateAttitude(const SensorSample& s, double dt) {
  const bool aligning = (s.t_s - t_start_s_) < params_.align_time_s;
  const double gain_boost = aligning ? 10.0 : 1.0;
  Vec3 corr = Vec3::Zero();     // rad/s, body
  Vec3 bias_rate = Vec3::Zero();

  if (s.imu_fresh) {
    // Tilt: measured specific force vs the one expected from the GPS-derived acceleration.
    // Soft dead band on the (noisy, differentiated) GPS acceleration: in hover and cruise the
    // reference is plain gravity; only real manoeuvres shift it.
    const double ga = gps_acc_.norm();
    const Vec3 a_ref = ga > params_.gps_acc_deadband_mps2 ? Vec3(gps_acc_ * (1.0 - params_.gps_acc_deadband_mps2 / ga))
                                                          : Vec3::Zero();
    const Vec3 expected_w = a_ref + Vec3(0.0, 0.0, kGravity_mps2);
    const double fm = s.accel_mps2.norm();
    if (fm > 1e-3 && std::abs(fm - expected_w.norm()) < params_.acc_gate_mps2) {
      const Vec3 meas = s.accel_mps2 / fm;
      const Vec3 expect = q_.inverse() * expected_w.normalized();
      const Vec3 e = meas.cross(expect);
      corr += gain_boost * params_.acc_kp * e;
      bias_rate -= params_.acc_ki * e;
    }
  }
  if (s.mag_fresh && s.mag_body.norm() > 1e-9) {
    // Heading only: compare horizontal directions in the world, correct about world z.
    const Vec3 m_w = q_ * s.mag_body;
    const double ref = std::atan2(params_.mag_field_world.y(), params_.mag_field_world.x());
    if (std::hypot(m_w.x(), m_w.y()) > 1e-6) {
      const double err = WrapPi(ref - std::atan2(m_w.y(), m_w.x()));  // yaw to add [rad]
      // The estimate's yaw is short by err: turn it about world z, expressed in the body.
      const Vec3 e_b = q_.inverse() * Vec3(0.0, 0.0, err);
      corr += gain_boost * params_.mag_kp * e_b;
      bias_rate -= params_.mag_ki * e_b;
    }
  }
  if (!aligning) gyro_bias_ += bias_rate * dt;
  for (int a = 0; a < 3; ++a) gyro_bias_[a] = std::clamp(gyro_bias_[a], -0.1, 0.1);
  const Vec3 w = s.gyro_radps - gyro_bias_ + corr;
  q_ = (q_ * ExpMap(w * dt)).normalized();
  state_.rate_radps = s.gyro_radps - gyro_bias_;
}

void Estimator::Predict(Axis* ax, double acc, double dt) const {
  Eigen::Matrix4d f = Eigen::Matrix4d::Identity();
  f(kP, kV) = dt;
  f(kP, kBa) = -0.5 * dt * dt;
  f(kV, kBa) = -dt;
  Eigen::Vector4d& x = ax->x;
  x(kP) += x(kV) * dt + 0.5 * (acc - x(kBa)) * dt * dt;
  x(kV) += (acc - x(kBa)) * dt;
  // Glide in the pending GPS corrections at bounded rates.
  const double dp = std::clamp(ax->pending_p, -params_.max_pos_correction_mps * dt, params_.max_pos_correction_mps * dt);
  const double dv = std::clamp(ax->pending_v, -params_.max_vel_correction_mps2 * dt, params_.max_vel_correction_mps2 * dt);
  x(kP) += dp;
  x(kV) += dv;
  ax->pending_p -= dp;
  ax->pending_v -= dv;
  Eigen::Matrix4d q = Eigen::Matrix4d::Zero();
  const double qa = params_.accel_noise_mps2 * params_.accel_noise_mps2;
  q(kP, kP) = 0.25 * dt * dt * dt * dt * qa;
  q(kP, kV) = q(kV, kP) = 0.5 * dt * dt * dt * qa;
  q(kV, kV) = dt * dt * qa;
  q(kBa, kBa) = params_.accel_bias_walk * params_.accel_bias_walk * dt;
  q(kBb, kBb) = params_.baro_bias_walk * params_.baro_bias_walk * dt;
  ax->p = f * ax->p * f.transpose() + q;
  if (ax->n < 4) {
    ax->p.row(kBb).setZero();
    ax->p.col(kBb).setZero();
  }
}

void Estimator::Correct(Axis* ax, double z, double r, bool with_baro_bias, int idx, bool glide) const {
  Eigen::RowVector4d h = Eigen::RowVector4d::Zero();
  h(idx) = 1.0;
  if (with_baro_bias) h(kBb) = 1.0;
  const double innov = z - h.dot(ax->x);
  const double s = h * ax->p * h.transpose() + r;
  if (!(s > 0.0)) return;
  const Eigen::Vector4d k = ax->p * h.transpose() / s;
  Eigen::Vector4d dx = k * innov;
  if (glide) {
    // Position and velocity corrections are not applied at once but handed to Predict(), which
    // applies them at a bounded rate (a glide, no step for the controller); the covariance is
    // updated now, as if applied.
    ax->pending_p += dx(kP);
    ax->pending_v += dx(kV);
    dx(kP) = 0.0;
    dx(kV) = 0.0;
  }
  ax->x += dx;
  // Joseph form keeps P symmetric and positive.
  const Eigen::Matrix4d ikh = Eigen::Matrix4d::Identity() - k * h;
  ax->p = ikh * ax->p * ikh.transpose() + k * r * k.transpose();
}

const StateEstimate& Estimator::Update(const SensorSample& s) {
  if (!att_init_) {
    // Wait for the accelerometer and the magnetometer (heading), or 0.5 s without a magnetometer.
    if (!s.imu_fresh) return state_;
    if (first_t_s_ < 0.0) first_t_s_ = s.t_s;
    if (!s.mag_fresh && s.t_s - first_t_s_ < 0.5) return state_;
    t_start_s_ = s.t_s;
    t_last_s_ = s.t_s;
    InitAttitude(s);
  }
  const double dt = std::clamp(s.t_s - t_last_s_, 0.0, 0.1);
  t_last_s_ = s.t_s;

  // GPS-derived acceleration for the tilt reference (zero when GPS is lost: hover assumption).
  if (s.gps_fresh && s.gps_valid) {
    if (last_gps_vel_t_s_ >= 0.0 && s.t_s - last_gps_vel_t_s_ > 1e-3 && s.t_s - last_gps_vel_t_s_ < 0.5) {
      const Vec3 a = (s.gps_vel_mps - last_gps_vel_) / (s.t_s - last_gps_vel_t_s_);
      const double alpha = std::min(1.0, (s.t_s - last_gps_vel_t_s_) / params_.gps_acc_tau_s);
      gps_acc_ += alpha * (a - gps_acc_);
    }
    last_gps_vel_ = s.gps_vel_mps;
    last_gps_vel_t_s_ = s.t_s;
  } else if (s.t_s - last_gps_vel_t_s_ > params_.gps_timeout_s) {
    gps_acc_ *= std::max(0.0, 1.0 - dt / params_.gps_acc_tau_s);
  }

  UpdateAttitude(s, dt);

  // World acceleration from the IMU, gravity removed.
  if (s.imu_fresh) acc_world_ = q_ * s.accel_mps2 - Vec3(0.0, 0.0, kGravity_mps2);

  if (!pos_init_) {
    const bool have_gps = s.gps_fresh && s.gps_valid;
    if (params_.has_initial_pos || have_gps) {
      const Vec3 p0 = params_.has_initial_pos ? params_.initial_pos_m : s.gps_pos_m;
      const double std_h = params_.has_initial_pos ? params_.initial_pos_std_m : params_.gps_pos_h_std_m;
      const double std_v = params_.has_initial_pos ? params_.initial_pos_std_m : params_.gps_pos_v_std_m;
      for (int a = 0; a < 3; ++a) {
        Axis& ax = ax_[a];
        ax.x.setZero();
        ax.p.setZero();
        ax.x(kP) = p0[a];
        ax.x(kV) = have_gps ? s.gps_vel_mps[a] : 0.0;
        const double sp = a == 2 ? std_v : std_h;
        ax.p(kP, kP) = sp * sp;
        ax.p(kV, kV) = 0.5 * 0.5;
        ax.p(kBa, kBa) = 0.2 * 0.2;
      }
      // Barometer offset: anchored at the start altitude (its own uncertainty).
      ax_[2].x(kBb) = baro_seen_ ? baro_pending_ - p0.z() : 0.0;
      ax_[2].p(kBb, kBb) = baro_seen_ ? std_v * std_v : 100.0;
      pos_init_ = true;
      if (have_gps) t_last_gps_s_ = s.t_s;
    }
  }
  if (s.baro_fresh) {
    if (!baro_seen_) {
      baro_seen_ = true;
      if (pos_init_) {
        ax_[2].x(kBb) = s.baro_alt_m - ax_[2].x(kP);
        ax_[2].p(kBb, kBb) = ax_[2].p(kP, kP);
      }
    }
    baro_pending_ = s.baro_alt_m;
  }

  if (pos_init_) {
    for (int a = 0; a < 3; ++a) Predict(&ax_[a], acc_world_[a], dt);
    if (s.baro_fresh) {
      Correct(&ax_[2], s.baro_alt_m, params_.baro_std_m * params_.baro_std_m, true, kP, false);
    }
    if (at_rest_ && ++rest_count_ >= 5) {  // 50 Hz zero-velocity update
      rest_count_ = 0;
      for (int a = 0; a < 3; ++a) Correct(&ax_[a], 0.0, 0.02 * 0.02, false, kV, false);
    }
    if (s.gps_fresh && s.gps_valid) {
      for (int a = 0; a < 3; ++a) {
        const double rp = a == 2 ? params_.gps_pos_v_std_m : params_.gps_pos_h_std_m;
        Correct(&ax_[a], s.gps_vel_mps[a], params_.gps_vel_std_mps * params_.gps_vel_std_mps, false, kV, true);
        Correct(&ax_[a], s.gps_pos_m[a], rp * rp, false, kP, true);
      }
      t_last_gps_s_ = s.t_s;
    }
  }

  for (int a = 0; a < 3; ++a) {
    state_.pos_m[a] = ax_[a].x(kP);
    state_.vel_mps[a] = ax_[a].x(kV);
    acc_bias_[a] = ax_[a].x(kBa);
    state_.accel_mps2[a] = acc_world_[a] - ax_[a].x(kBa);
    state_.pos_std_m[a] = std::sqrt(std::max(0.0, ax_[a].p(kP, kP)));
  }
  state_.t_s = s.t_s;
  state_.att = q_;
  state_.since_gps_s = s.t_s - t_last_gps_s_;
  state_.gps_ok = pos_init_ && state_.since_gps_s < params_.gps_timeout_s;
  state_.valid = att_init_ && pos_init_ && (s.t_s - t_start_s_) >= params_.align_time_s;
  return state_;
}

}  // namespace swarmbox::flight
