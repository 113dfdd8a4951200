#include "swarmbox/flight/estimator.hpp"

#include <algorithm>
#include <cmath>

namespace swarmbox::flight {
namespace {

constexpr int kP = 0;  // state indices of an axis filter
constexpr int kV = 1;
constexpr int kBa = 2;
constexpr int kBg = 3;
constexpr int kBb = 4;

Quat ExpMap(const Vec3& w_dt) {
  const double a = w_dt.norm();
  if (a < 1e-9) return Quat(1.0, 0.5 * w_dt.x(), 0.5 * w_dt.y(), 0.5 * w_dt.z()).normalized();
  const Vec3 axis = w_dt / a;
  return Quat(Eigen::AngleAxisd(a, axis));
}

}  // namespace

Estimator::Estimator(const EstimatorParams& params) : params_(params) {
  for (int a = 0; a < 3; ++a) ax_[a].n = (a == 2) ? 5 : 4;
}

void Estimator::InitAttitude(const SensorSample& s) {
  // Tilt from gravity (the drone is assumed still at power-up), heading from the magnetometer.
  const Vec3 up_b = s.accel_m_s2.norm() > 1e-3 ? Vec3(s.accel_m_s2.normalized()) : Vec3::UnitZ();
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
  // Aligning, or standing still on the ground: the accelerometer is a clean gravity reference,
  // so correct tilt ten times faster and learn the gyro biases fifty times faster: PI poles
  // at ~1 rad/s (time constant kp / ki ~1.5 s) instead of ~0.14 rad/s in flight, where the
  // accelerometer also sees manoeuvres.
  const bool still = aligning || at_rest_;
  const double gain_boost = still ? 10.0 : 1.0;
  const double bias_boost = still ? 50.0 : 1.0;
  Vec3 corr = Vec3::Zero();     // rad/s, body
  Vec3 bias_rate = Vec3::Zero();
  Vec3 e;
  if (s.imu_fresh && TiltError(s, &e)) {
    corr += gain_boost * params_.acc_kp * e;
    bias_rate -= bias_boost * params_.acc_ki * e;
  }
  if (HeadingError(s, &e)) {
    corr += gain_boost * params_.mag_kp * e;
    bias_rate -= bias_boost * params_.mag_ki * e;
  }
  if (!aligning) gyro_bias_ += bias_rate * dt;
  for (int a = 0; a < 3; ++a) gyro_bias_[a] = std::clamp(gyro_bias_[a], -0.1, 0.1);
  const Vec3 w = s.gyro_rad_s - gyro_bias_ + corr;
  q_ = (q_ * ExpMap(w * dt)).normalized();
  state_.rate_rad_s = s.gyro_rad_s - gyro_bias_;
}

Vec3 Estimator::TiltReference(const SensorSample& s) const {
  // Tilt: measured specific force vs the one expected from the vehicle's acceleration. At
  // rest the reference is plain gravity. In flight, either
  //  * the translational filter's acceleration (IMU minus the world-frame bias that GPS
  //    velocity reveals): a tilt error shows there as a horizontal bias of g times the error,
  //    so this closes the tilt-from-GPS-velocity loop of a full INS filter, without lag; or
  //  * differentiated GPS velocity, low-passed, with a soft dead band (hover and cruise: plain
  //    gravity): lagged, but blind to what a swinging slung load does to the filter's bias.
  Vec3 a_ref = Vec3::Zero();
  // Without GPS (lost for longer than gps_timeout_s) nothing observes that bias: hover
  // assumption, plain gravity, as the GPS-derived reference decays to.
  const bool gps_recent = s.t_s - t_last_gps_s_ < params_.gps_timeout_s;
  if (!at_rest_ && pos_init_) {
    if (params_.tilt_ref_from_filter && gps_recent) {
      a_ref = state_.accel_m_s2;
    } else if (const double ga = gps_acc_.norm(); ga > params_.gps_acc_deadband_m_s2) {
      a_ref = gps_acc_ * (1.0 - params_.gps_acc_deadband_m_s2 / ga);
    }
  }
  return a_ref + Vec3(0.0, 0.0, kGravity_m_s2);
}

bool Estimator::TiltError(const SensorSample& s, Vec3* e) const {
  const Vec3 expected_w = TiltReference(s);
  const double fm = s.accel_m_s2.norm();
  if (!(fm > 1e-3 && std::abs(fm - expected_w.norm()) < params_.acc_gate_m_s2)) return false;
  const Vec3 meas = s.accel_m_s2 / fm;
  const Vec3 expect = q_.inverse() * expected_w.normalized();
  *e = meas.cross(expect);
  return true;
}

bool Estimator::HeadingError(const SensorSample& s, Vec3* e_b) const {
  if (!(s.mag_fresh && s.mag_body.norm() > 1e-9)) return false;
  // Heading only: compare horizontal directions in the world, correct about world z.
  const Vec3 m_w = q_ * s.mag_body;
  const double ref = std::atan2(params_.mag_field_world.y(), params_.mag_field_world.x());
  if (!(std::hypot(m_w.x(), m_w.y()) > 1e-6)) return false;
  const double err = WrapPi(ref - std::atan2(m_w.y(), m_w.x()));  // yaw to add [rad]
  // The estimate's yaw is short by err: turn it about world z, expressed in the body.
  *e_b = q_.inverse() * Vec3(0.0, 0.0, err);
  return true;
}

void Estimator::Predict(Axis* ax, int axis, double acc, double dt) const {
  Mat5 f = Mat5::Identity();
  f(kP, kV) = dt;
  f(kP, kBa) = -0.5 * dt * dt;
  f(kV, kBa) = -dt;
  Vec5& x = ax->x;
  x(kP) += x(kV) * dt + 0.5 * (acc - x(kBa)) * dt * dt;
  x(kV) += (acc - x(kBa)) * dt;
  Mat5 q = Mat5::Zero();
  const double qa = params_.accel_noise_m_s2 * params_.accel_noise_m_s2;
  q(kP, kP) = 0.25 * dt * dt * dt * dt * qa;
  // In flight the horizontal position lives in the receiver's (wandering) frame; standing on the
  // ground the drone is known not to move, and the GPS error state takes the wander instead.
  const double fw = params_.gps_frame_walk_h * gps_scale_h_;
  if (axis != 2) {
    const double w = at_rest_ ? fw : 0.0;
    q(kP, kP) += fw * fw * dt - w * w * dt;
    q(kBg, kBg) += w * w * dt;
  }
  q(kP, kV) = q(kV, kP) = 0.5 * dt * dt * dt * qa;
  q(kV, kV) = dt * dt * qa;
  q(kBa, kBa) = params_.accel_bias_walk * params_.accel_bias_walk * dt;
  const double gw =
      axis == 2 ? params_.gps_bias_walk_v * gps_scale_v_ : params_.gps_bias_walk_h * gps_scale_h_;
  q(kBg, kBg) = gw * gw * dt;
  q(kBb, kBb) = params_.baro_bias_walk * params_.baro_bias_walk * dt;
  ax->p = f * ax->p * f.transpose() + q;
  if (ax->n < 5) {
    ax->p.row(kBb).setZero();
    ax->p.col(kBb).setZero();
  }
  // The output glides after the corrections at bounded rates.
  ax->out_dp -= std::clamp(ax->out_dp, -params_.max_pos_correction_m_s * dt, params_.max_pos_correction_m_s * dt);
  ax->out_dv -= std::clamp(ax->out_dv, -params_.max_vel_correction_m_s2 * dt, params_.max_vel_correction_m_s2 * dt);
}

void Estimator::Correct(Axis* ax, const Row5& h, double y, double r) const {
  const double s = (h * ax->p * h.transpose())(0, 0) + r;
  if (!(s > 0.0) || !std::isfinite(y)) return;
  const Vec5 k = ax->p * h.transpose() / s;
  const Vec5 dx = k * y;
  ax->x += dx;
  // Joseph form keeps P symmetric and positive.
  const Mat5 ikh = Mat5::Identity() - k * h;
  ax->p = ikh * ax->p * ikh.transpose() + k * r * k.transpose();
  // The history moves with the correction, mapped back through the motion model.
  const double t_now = hist_t_[HistIndex(0)];
  for (std::size_t age = 0; age < hist_count_; ++age) {
    const std::size_t i = HistIndex(age);
    const double d = t_now - hist_t_[i];
    ax->hist_p[i] += dx(kP) - dx(kV) * d - 0.5 * dx(kBa) * d * d;
    ax->hist_v[i] += dx(kV) + dx(kBa) * d;
  }
  // The output does not jump: it catches up in Predict().
  ax->out_dp += dx(kP);
  ax->out_dv += dx(kV);
}

void Estimator::TakeGpsAccuracy(const SensorSample& s) {
  const auto noise = [](double reported, double white, double floor) {
    return reported > 0.0 ? std::max(floor, std::min(white, reported)) : white;
  };
  const auto scale = [](double reported, double nominal) {
    return reported > 0.0 && nominal > 0.0 ? std::min(1.0, reported / nominal) : 1.0;
  };
  gps_r_h_m_ = noise(s.gps_eph_m, params_.gps_noise_h_m, params_.gps_noise_floor_h_m);
  gps_r_v_m_ = noise(s.gps_epv_m, params_.gps_noise_v_m, params_.gps_noise_floor_v_m);
  gps_scale_h_ = scale(s.gps_eph_m, params_.gps_pos_h_std_m);
  gps_scale_v_ = scale(s.gps_epv_m, params_.gps_pos_v_std_m);
  if (gps_prior_taken_) return;
  gps_prior_taken_ = true;
  // The error state's prior was the airframe's accuracy; a receiver reporting better (RTK) narrows
  // it before its first fix is fused. P -> D P D with D = 1 but c on the error state keeps P
  // positive (semi-)definite; with a report of the airframe's figure c = 1 and nothing changes.
  for (int a = 0; a < 3; ++a) {
    const double reported = a == 2 ? s.gps_epv_m : s.gps_eph_m;
    const double var = ax_[a].p(kBg, kBg);
    if (!(reported > 0.0) || !(reported * reported < 0.99 * var)) continue;
    const double c = reported / std::sqrt(var);
    ax_[a].p.row(kBg) *= c;
    ax_[a].p.col(kBg) *= c;
  }
}

const StateEstimate& Estimator::Update(const SensorSample& s) {
  if (!att_init_ && !StartAttitude(s)) return state_;
  const double dt = std::clamp(s.t_s - t_last_s_, 0.0, 0.1);
  t_last_s_ = s.t_s;
  TrackGpsAcceleration(s, dt);
  UpdateAttitude(s, dt);
  // World acceleration from the IMU, gravity removed.
  if (s.imu_fresh) acc_world_ = q_ * s.accel_m_s2 - Vec3(0.0, 0.0, kGravity_m_s2);
  if (!pos_init_) InitPosition(s);
  TakeBaro(s);
  if (pos_init_) {
    for (int a = 0; a < 3; ++a) Predict(&ax_[a], a, acc_world_[a], dt);
    PushHistory(s.t_s);
    if (s.baro_fresh) {
      Row5 h = Row5::Zero();
      h(kP) = 1.0;
      h(kBb) = 1.0;
      Correct(&ax_[2], h, s.baro_alt_m - ax_[2].x(kP) - ax_[2].x(kBb), params_.baro_std_m * params_.baro_std_m);
    }
    if (at_rest_ && ++rest_count_ >= 5) {  // 50 Hz zero-velocity update
      rest_count_ = 0;
      Row5 h = Row5::Zero();
      h(kV) = 1.0;
      for (Axis& ax : ax_) Correct(&ax, h, -ax.x(kV), 0.02 * 0.02);
    }
    if (s.gps_fresh && s.gps_valid) FuseGps(s);
  }
  Publish(s);
  return state_;
}

bool Estimator::StartAttitude(const SensorSample& s) {
  // Wait for the accelerometer and the magnetometer (heading), or 0.5 s without a magnetometer.
  if (!s.imu_fresh) return false;
  if (first_t_s_ < 0.0) first_t_s_ = s.t_s;
  if (!s.mag_fresh && s.t_s - first_t_s_ < 0.5) return false;
  t_start_s_ = s.t_s;
  t_last_s_ = s.t_s;
  InitAttitude(s);
  return true;
}

void Estimator::TrackGpsAcceleration(const SensorSample& s, double dt) {
  // GPS-derived acceleration for the tilt reference (zero when GPS is lost: hover assumption).
  if (s.gps_fresh && s.gps_valid) {
    if (last_gps_vel_t_s_ >= 0.0 && s.t_s - last_gps_vel_t_s_ > 1e-3 && s.t_s - last_gps_vel_t_s_ < 0.5) {
      const Vec3 a = (s.gps_vel_m_s - last_gps_vel_) / (s.t_s - last_gps_vel_t_s_);
      const double alpha = std::min(1.0, (s.t_s - last_gps_vel_t_s_) / params_.gps_acc_tau_s);
      gps_acc_ += alpha * (a - gps_acc_);
    }
    last_gps_vel_ = s.gps_vel_m_s;
    last_gps_vel_t_s_ = s.t_s;
  } else if (s.t_s - last_gps_vel_t_s_ > params_.gps_timeout_s) {
    gps_acc_ *= std::max(0.0, 1.0 - dt / params_.gps_acc_tau_s);
  }
}

void Estimator::InitPosition(const SensorSample& s) {
  const bool have_gps = s.gps_fresh && s.gps_valid;
  if (!params_.has_initial_pos && !have_gps) return;
  const Vec3 p0 = params_.has_initial_pos ? params_.initial_pos_m : s.gps_pos_m;
  for (int a = 0; a < 3; ++a) {
    Axis& ax = ax_[a];
    ax.x.setZero();
    ax.p.setZero();
    ax.x(kP) = p0[a];
    ax.x(kV) = have_gps ? s.gps_vel_m_s[a] : 0.0;
    const double total = a == 2 ? params_.gps_pos_v_std_m : params_.gps_pos_h_std_m;
    // Known start: the position is sure, the GPS error is what the receiver's spec says.
    // Else the first fix is all there is: position and GPS error share its uncertainty.
    const double sp = params_.has_initial_pos ? params_.initial_pos_std_m : total;
    ax.p(kP, kP) = sp * sp;
    ax.p(kV, kV) = 0.5 * 0.5;
    ax.p(kBa, kBa) = 0.2 * 0.2;
    ax.p(kBg, kBg) = total * total;
    // Started on a fix: p + b_gps is what was measured, so their errors cancel in the sum.
    if (!params_.has_initial_pos) ax.p(kP, kBg) = ax.p(kBg, kP) = -0.99 * total * total;
    ax.out_dp = ax.out_dv = 0.0;
  }
  // Barometer offset: anchored at the start altitude (its own uncertainty).
  ax_[2].x(kBb) = baro_seen_ ? baro_pending_ - p0.z() : 0.0;
  ax_[2].p(kBb, kBb) = baro_seen_ ? params_.gps_pos_v_std_m * params_.gps_pos_v_std_m : 100.0;
  pos_init_ = true;
  if (have_gps) t_last_gps_s_ = s.t_s;
}

void Estimator::TakeBaro(const SensorSample& s) {
  if (!s.baro_fresh) return;
  if (!baro_seen_) {
    baro_seen_ = true;
    if (pos_init_) {
      ax_[2].x(kBb) = s.baro_alt_m - ax_[2].x(kP);
      ax_[2].p(kBb, kBb) = ax_[2].p(kP, kP) + params_.baro_std_m * params_.baro_std_m;
    }
  }
  baro_pending_ = s.baro_alt_m;
}

void Estimator::PushHistory(double t_s) {
  // History: this step's position and velocity.
  hist_head_ = (hist_head_ + 1) % kHistory;
  hist_count_ = std::min(hist_count_ + 1, kHistory);
  hist_t_[HistIndex(0)] = t_s;
  for (Axis& ax : ax_) {
    ax.hist_p[HistIndex(0)] = ax.x(kP);
    ax.hist_v[HistIndex(0)] = ax.x(kV);
  }
}

void Estimator::FuseGps(const SensorSample& s) {
  TakeGpsAccuracy(s);
  // The state of the fix's epoch: the newest history slot at least gps_delay_s old.
  std::size_t age = 0;
  while (age + 1 < hist_count_ && s.t_s - hist_t_[HistIndex(age)] < params_.gps_delay_s - 1e-6) ++age;
  const std::size_t i = HistIndex(age);
  const double d = s.t_s - hist_t_[i];
  for (int a = 0; a < 3; ++a) {
    Axis& ax = ax_[a];
    // Velocity: v(t - d) = v + d b_acc (+ known inputs, in the history).
    Row5 hv = Row5::Zero();
    hv(kV) = 1.0;
    hv(kBa) = d;
    Correct(&ax, hv, s.gps_vel_m_s[a] - ax.hist_v[i], params_.gps_vel_std_m_s * params_.gps_vel_std_m_s);
    // Position: p(t - d) + b_gps, p(t - d) = p - d v - d^2/2 b_acc (+ known inputs).
    Row5 hp = Row5::Zero();
    hp(kP) = 1.0;
    hp(kV) = -d;
    hp(kBa) = -0.5 * d * d;
    hp(kBg) = 1.0;
    const double rn = a == 2 ? gps_r_v_m_ : gps_r_h_m_;
    Correct(&ax, hp, s.gps_pos_m[a] - ax.hist_p[i] - ax.x(kBg), rn * rn);
  }
  t_last_gps_s_ = s.t_s;
}

void Estimator::Publish(const SensorSample& s) {
  for (int a = 0; a < 3; ++a) {
    state_.pos_m[a] = ax_[a].x(kP) - ax_[a].out_dp;
    state_.vel_m_s[a] = ax_[a].x(kV) - ax_[a].out_dv;
    acc_bias_[a] = ax_[a].x(kBa);
    state_.accel_m_s2[a] = acc_world_[a] - ax_[a].x(kBa);
    state_.pos_std_m[a] = std::sqrt(std::max(0.0, ax_[a].p(kP, kP)));
  }
  state_.t_s = s.t_s;
  state_.att = q_;
  state_.since_gps_s = s.t_s - t_last_gps_s_;
  state_.gps_ok = pos_init_ && state_.since_gps_s < params_.gps_timeout_s;
  state_.valid = att_init_ && pos_init_ && (s.t_s - t_start_s_) >= params_.align_time_s;
}

}  // namespace swarmbox::flight
