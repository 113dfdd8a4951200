// State estimation from the sensor sample alone (IMU, barometer, magnetometer, GPS).
//
// Design (why not a full EKF): the attitude and the translational states are split, which keeps
// each part small, allocation-free and easy to tune and test:
//  * Attitude: a Mahony complementary filter on SO(3) with gyro-bias integration. Gyros propagate;
//    the accelerometer corrects tilt against the *expected* specific force q^-1 (a_world + g z),
//    where a_world is the translational filter's acceleration (IMU minus the bias GPS velocity
//    reveals, so GPS velocity corrects tilt as in a full INS filter) or differentiated GPS
//    velocity (per airframe), so tilt is not pulled towards level while the drone accelerates,
//    the classic complementary-filter failure on multirotors;
//    the magnetometer corrects heading only (its horizontal projection), never tilt.
//  * Translation: one linear Kalman filter per world axis, driven by the IMU's world-frame
//    acceleration, states [position, velocity, accelerometer bias, GPS position error] (+ the
//    barometer offset on z), fusing GPS position and velocity, barometric altitude and, on the
//    ground, zero-velocity updates. Per-axis filters are exact for this linear model and give
//    honest, growing uncertainty during GPS dropouts (dead reckoning on the IMU with the bias
//    learnt before; the barometer keeps altitude).
//  * The GPS error is a state because a real receiver's error is not white: it is dominated by
//    offsets that wander over minutes (atmosphere, multipath). Horizontally the state holds the
//    offset between the receiver's frame and a known start point (a surveyed take-off spot, as
//    PX4's home), learnt on the ground; in flight the position follows the receiver (over
//    seconds its wander cannot be told from motion). Vertically it is a random walk as fast as
//    the receiver's wander, so height follows the barometer and GPS only anchors it.
//  * The receiver's reported accuracy (eph/epv) sets how much a fix is trusted, as in PX4's
//    EKF2 (position noise max(EKF2_GPS_P_NOISE, eph)): per fix, the measurement noise is
//    max(gps_noise_floor, min(gps_noise, eph)) (a standalone receiver's 0.8 m report is mostly
//    its slow error, which the error state carries; its fix-to-fix part is gps_noise, 0.2 m), and
//    the receiver-error processes (gps_frame_walk_h, gps_bias_walk_*) and the error state's prior
//    scale with eph / gps_pos_std (at most 1). A standalone fix reporting the airframe's accuracy
//    is fused exactly as without the report; an RTK-fixed one (eph ~0.01 m) is followed to the
//    centimetre, with no hand-set gain.
//  * GPS delay: fixes describe the vehicle `gps_delay_s` ago (PX4's EKF2_GPS_DELAY). A short
//    history of the state is kept; a fix is compared with the state of its epoch, and the
//    correction maps to the present through the motion model (H * Phi(-delay)), as PX4's EKF2
//    fuses delayed measurements on a delayed horizon and predicts forward.
//  * Output smoothing: every correction is applied to the filter at once (it stays consistent);
//    what the controllers see glides after it at most at `max_pos_correction_m_s` /
//    `max_vel_correction_m_s2`. In steady fusion that is invisible (millimetres per fix); after
//    a dropout the estimate glides back to the GPS instead of jumping, so the controller is not
//    kicked.
//
//   Estimator est(EstimatorParams{});
//   for each sample: const StateEstimate& s = est.Update(sample);  // valid once aligned
#pragma once

#include <array>
#include <cstddef>

#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {

struct EstimatorParams {
  // Attitude filter.
  double acc_kp = 0.15;             // tilt correction gain [rad/s per unit vector error]
  double acc_ki = 0.02;             // gyro bias gain [rad/s^2 per unit error]
  double mag_kp = 0.3;              // heading correction gain [(rad/s)/rad]
  double mag_ki = 0.01;             // yaw gyro bias gain [(rad/s^2)/rad]
  double align_time_s = 1.0;        // high-gain alignment period after start [s]
  double acc_gate_m_s2 = 2.5;       // skip tilt correction when |f| differs from expected by more
  bool tilt_ref_from_filter = true;  // tilt reference in flight: the filter's acceleration, or
                                    // (false) differentiated GPS velocity; see UpdateAttitude
  double gps_acc_tau_s = 0.5;       // low-pass of the GPS-derived acceleration [s]
  double gps_acc_deadband_m_s2 = 0.3;  // soft dead band on it [m/s^2]
  Vec3 mag_field_world = Vec3(0.0, 0.21, -0.42);  // Earth field, ENU (only its horizontal
                                                   // direction matters) [gauss]
  // Translational Kalman filters.
  double accel_noise_m_s2 = 0.2;   // process noise on the IMU-derived acceleration [m/s^2]
                                   // (EKF2_ACC_NOISE; covers attitude errors too)
  double accel_bias_walk = 0.01;    // bias random walk [m/s^2 / sqrt(s)] (EKF2_ACC_B_NOISE)
  double baro_bias_walk = 0.003;     // barometer offset random walk [m / sqrt(s)]
  double gps_pos_h_std_m = 0.8;     // total GPS accuracy, 1 sigma per axis (the airframe's GPS
  double gps_pos_v_std_m = 1.5;     // spec): the prior of the GPS error state [m]
  double gps_noise_h_m = 0.2;       // fix-to-fix (white) GPS noise (EKF2_GPS_P_NOISE) [m]
  double gps_noise_v_m = 0.5;
  double gps_noise_floor_h_m = 0.01;   // the least GPS noise assumed whatever the receiver reports
  double gps_noise_floor_v_m = 0.015;  // (EKF2_GPS_P_NOISE's lower bound 0.01; vertically 1.5x, as
                                       // EKF2 fuses GPS height) [m]
  double gps_bias_walk_h = 0.002;   // GPS error random walk [m / sqrt(s)]. Horizontally ~0: the
                                    // state holds the offset learnt at a known start, and the
                                    // position follows the receiver's wander (seconds cannot
                                    // tell it from motion; PX4's EKF2 follows GPS the same way).
  double gps_frame_walk_h = 0.046;  // the receiver frame's horizontal wander (multipath), as a
                                    // random walk of the position itself, sqrt(2 0.25^2 / 60 s)
                                    // [m / sqrt(s)]: what lets the position follow it
  double gps_bias_walk_v = 0.11;    // Vertically the wander's, sqrt(2 0.55^2 / 60 s): height
                                    // follows the barometer, GPS only anchors it.
  double gps_delay_s = 0.12;        // age of a fix when it arrives (EKF2_GPS_DELAY) [s]
  double gps_vel_std_m_s = 0.1;     // GPS velocity noise (EKF2_GPS_V_NOISE) [m/s]
  double baro_std_m = 0.15;
  double gps_timeout_s = 0.5;       // no fix for this long: GPS lost
  double max_pos_correction_m_s = 1.0;    // slew limit of the position correction [m/s]
  double max_vel_correction_m_s2 = 1.0;   // slew limit of the velocity correction [m/s^2]
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
  // The estimated GPS position error (fix minus true position), world ENU [m].

 private:
  using Vec5 = Eigen::Matrix<double, 5, 1>;
  using Mat5 = Eigen::Matrix<double, 5, 5>;
  using Row5 = Eigen::Matrix<double, 1, 5>;
  static constexpr std::size_t kHistory = 128;  // >= gps_delay_s / control period (0.5 s at 4 ms)
  // Per-axis Kalman filter, states [p, v, b_acc, b_gps, b_baro], the last used on z only, and
  // the history of its position and velocity for delayed measurements.
  struct Axis {
    Vec5 x = Vec5::Zero();
    Mat5 p = Mat5::Zero();
    int n = 4;  // states in use
    double out_dp = 0.0;  // corrections not yet passed to the output [m], [m/s]
    double out_dv = 0.0;
    std::array<double, kHistory> hist_p{}, hist_v{};
  };
  // Update's steps, in order (each allocation-free, in the estimator's translation unit).
  bool StartAttitude(const SensorSample& s);  // false while waiting for the first samples
  void InitAttitude(const SensorSample& s);
  void TrackGpsAcceleration(const SensorSample& s, double dt);
  void UpdateAttitude(const SensorSample& s, double dt);
  // The expected specific force in the world (gravity plus the reference acceleration) [m/s^2].
  Vec3 TiltReference(const SensorSample& s) const;
  // The attitude errors the accelerometer and the magnetometer see (body frame) [rad]; false
  // when the sample gives none (gated out, no fresh field).
  bool TiltError(const SensorSample& s, Vec3* e) const;
  bool HeadingError(const SensorSample& s, Vec3* e_b) const;
  void InitPosition(const SensorSample& s);  // on the initial position or the first fix
  void TakeBaro(const SensorSample& s);
  void PushHistory(double t_s);
  void FuseGps(const SensorSample& s);       // the delayed fix, against the history
  void Publish(const SensorSample& s);       // state_ from the filters
  void Predict(Axis* ax, int axis, double acc, double dt) const;
  // Scalar measurement with row h, innovation y, variance r; the correction is also carried into
  // the history (mapped back through the motion model) and into the output glide.
  void Correct(Axis* ax, const Row5& h, double y, double r) const;
  // Takes the receiver's reported accuracy of a fix (see the header comment).
  void TakeGpsAccuracy(const SensorSample& s);
  // History slot `age` steps back (0 = now) and its age [s].
  std::size_t HistIndex(std::size_t age) const { return (hist_head_ + kHistory - 1 - age) % kHistory; }

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
  std::array<double, kHistory> hist_t_{};  // times of the history slots [s]
  std::size_t hist_head_ = 0;
  std::size_t hist_count_ = 0;
  double baro_pending_ = 0.0;
  bool baro_seen_ = false;
  bool at_rest_ = false;
  int rest_count_ = 0;
  // From the last fix's reported accuracy: the receiver-error processes' scale (<= 1) and the
  // measurement noise [m], horizontal and vertical.
  double gps_scale_h_ = 1.0, gps_scale_v_ = 1.0;
  double gps_r_h_m_ = 0.0, gps_r_v_m_ = 0.0;
  bool gps_prior_taken_ = false;  // the error state's prior has met the first report
};

}  // namespace swarmbox::flight
