// State estimation from the sensor sample alone (IMU, barometer, magnetometer, GPS).
//
// Design (why not a full EKF): the attitude and the translational states are split, which keeps
// each part small, allocation-free and easy to tune and test:
//  * Attitude: a Mahony complementary filter on SO(3) with gyro-bias integration. Gyros propagate;
//    the accelerometer corrects tilt against the *expected* specific force q^-1 (a_world + g z),
//    where a_world comes from differentiated GPS velocity (so tilt is not pulled towards level
//    while the drone accelerates, the classic complementary-filter failure on multirotors);
//    the magnetometer corrects heading only (its horizontal projection), never tilt.
//  * Translation: one linear Kalman filter per world axis, driven by the IMU's world-frame
//    acceleration, states [position, velocity, acceleration bias] (+ barometer offset on z),
//    fusing GPS position/velocity and barometric altitude. Per-axis filters are exact for this
//    linear model and give honest, growing uncertainty during GPS dropouts (dead reckoning on
//    the IMU with the bias learnt before the dropout; the barometer keeps altitude).
//  * GPS corrections glide in: the position/velocity change a fix asks for is applied over the
//    following steps at most at `max_pos_correction_mps` / `max_vel_correction_mps2`. In steady
//    fusion that is invisible (centimetres); after a dropout the estimate glides back to the GPS
//    instead of jumping, so the controller is not kicked.
//
//   Estimator est(EstimatorParams{});
//   for each sample: const StateEstimate& s = est.Update(sample);  // valid once aligned
#pragma once

#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {

struct EstimatorParams {
  // Attitude filter.
  double acc_kp = 0.15;             // tilt correction gain [rad/s per unit vector error]
  double acc_ki = 0.02;             // gyro bias gain [rad/s^2 per unit error]
  double mag_kp = 0.3;              // heading correction gain [(rad/s)/rad]
  double mag_ki = 0.01;             // yaw gyro bias gain [(rad/s^2)/rad]
  double align_time_s = 1.0;        // high-gain alignment period after start [s]
  double acc_gate_mps2 = 2.5;       // skip tilt correction when |f| differs from expected by more
  double gps_acc_tau_s = 0.5;       // low-pass of the GPS-derived acceleration [s]
  double gps_acc_deadband_mps2 = 0.3;  // soft dead band on it [m/s^2]
  Vec3 mag_field_world = Vec3(0.0, 0.21, -0.42);  // Earth field, ENU (only its horizontal
                                                   // direction matters) [gauss]
  // Translational Kalman filters.
  double accel_noise_mps2 = 0.2;   // process noise on the IMU-derived acceleration [m/s^2]
  double accel_bias_walk = 0.01;    // bias random walk [m/s^2 / sqrt(s)]
  double baro_bias_walk = 0.003;     // barometer offset random walk [m / sqrt(s)]
  double gps_pos_h_std_m = 0.8;     // measurement noise (from the airframe's GPS spec)
  double gps_pos_v_std_m = 1.5;
  double gps_vel_std_mps = 0.1;
  double baro_std_m = 0.15;
  double gps_timeout_s = 0.5;       // no fix for this long: GPS lost
  double max_pos_correction_mps = 1.0;    // slew limit of the position correction [m/s]
  double max_vel_correction_mps2 = 1.0;   // slew limit of the velocity correction [m/s^2]
  // Known start point (a surveyed take-off spot, as PX4's home): when set, the filter starts
  // there with `initial_pos_std_m` instead of on the first, noisy GPS fix; the barometer offset
  // is then anchored to the known start altitude.
  bool has_initial_pos = false;
  Vec3 initial_pos_m = Vec3::Zero();   // world ENU [m]
  double initial_pos_std_m = 0.05;
};

class Estimator {
 public:
  explicit Estimator(const EstimatorParams& params = {});
  const StateEstimate& Update(const SensorSample& s);
  // The vehicle is known to stand still (on the ground, motors off): zero-velocity updates let
  // the filter learn its biases before take-off (PX4 does the same while landed).
  void SetAtRest(bool at_rest) { at_rest_ = at_rest; }
  const StateEstimate& state() const { return state_; }
  const Vec3& gyro_bias() const { return gyro_bias_; }
  const Vec3& accel_bias_world() const { return acc_bias_; }

 private:
  // Per-axis Kalman filter, states [p, v, b_acc, b_baro], the last used on z only.
  struct Axis {
    Eigen::Vector4d x = Eigen::Vector4d::Zero();
    Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
    int n = 3;  // states in use
    double pending_p = 0.0;  // GPS corrections still to glide in [m], [m/s]
    double pending_v = 0.0;
  };
  void InitAttitude(const SensorSample& s);
  void UpdateAttitude(const SensorSample& s, double dt);
  void Predict(Axis* ax, double acc, double dt) const;
  // Measurement of state `idx` (plus the baro offset when `with_baro_bias`), variance r.
  // glide: position/velocity corrections are applied by Predict() at bounded rates.
  void Correct(Axis* ax, double z, double r, bool with_baro_bias, int idx, bool glide) const;

  EstimatorParams params_;
  StateEstimate state_;
  bool att_init_ = false;
  bool pos_init_ = false;
  double t_start_s_ = 0.0;
  double first_t_s_ = -1.0;
  double t_last_s_ = 0.0;
  double t_last_gps_s_ = -1e9;
  Quat q_ = Quat::Identity();
  Vec3 gyro_bias_ = Vec3::Zero();
  Vec3 acc_bias_ = Vec3::Zero();
  Vec3 gps_acc_ = Vec3::Zero();      // low-passed GPS-derived acceleration, ENU [m/s^2]
  Vec3 last_gps_vel_ = Vec3::Zero();
  double last_gps_vel_t_s_ = -1.0;
  Vec3 acc_world_ = Vec3::Zero();    // last IMU acceleration in the world, gravity removed
  Axis ax_[3];
  double baro_pending_ = 0.0;
  bool baro_seen_ = false;
  bool at_rest_ = false;
  int rest_count_ = 0;
};

}  // namespace swarmbox::flight
