// Shared value types of the flight stack: vectors, the sensor sample the estimator consumes and
// the state estimate the controllers consume.
//
// Frames and units (ARCHITECTURE.md): world frame ENU (x east, y north, z up) in metres, body frame
// FLU (x forward, y left, z up), quaternions (w, x, y, z) rotate body to world, SI units. Yaw is
// the heading of body x measured counter-clockwise from east [rad].
//
// These are the flight library's own types so that the pure libraries depend on neither the bus
// nor the physics library; the node (agent/app) and the closed-loop tests convert at the edge.
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace swarmbox::flight {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

constexpr double kGravity_m_s2 = 9.80665;
constexpr double kPi = 3.14159265358979323846;

// One lockstep sensor sample, as the companion computer sees it. Never ground truth.
// Each sensor runs at its own rate; `*_fresh` says a new reading arrived at this step.
struct SensorSample {
  double t_s = 0.0;                   // simulated time [s]
  bool imu_fresh = true;
  Vec3 accel_m_s2 = Vec3::Zero();     // specific force, body FLU [m/s^2] (reads +g on z at rest)
  Vec3 gyro_rad_s = Vec3::Zero();     // angular rate, body FLU [rad/s]
  bool baro_fresh = false;
  double baro_alt_m = 0.0;            // barometric altitude [m]; a constant offset is estimated
  bool mag_fresh = false;
  Vec3 mag_body = Vec3::Zero();       // magnetic field, body FLU (any unit: its direction is used)
  bool gps_fresh = false;             // a new GPS report (fix or no-fix) at this step
  bool gps_valid = false;             // the report has a fix (false during a dropout)
  Vec3 gps_pos_m = Vec3::Zero();      // position, world ENU [m]
  Vec3 gps_vel_m_s = Vec3::Zero();    // velocity, world ENU [m/s]
  double gps_eph_m = 0.0;             // the receiver's reported accuracy (u-blox hAcc, PX4's
  double gps_epv_m = 0.0;             // eph/epv): 1-sigma per horizontal axis / vertically [m];
                                      // 0: not reported
};

// The estimator's output, the controllers' input.
struct StateEstimate {
  double t_s = 0.0;
  Vec3 pos_m = Vec3::Zero();           // world ENU [m]
  Vec3 vel_m_s = Vec3::Zero();         // world ENU [m/s]
  Vec3 accel_m_s2 = Vec3::Zero();      // kinematic acceleration, world ENU [m/s^2] (gravity removed)
  Quat att = Quat::Identity();         // body FLU -> world ENU
  Vec3 rate_rad_s = Vec3::Zero();      // bias-corrected angular rate, body FLU [rad/s]
  Vec3 pos_std_m = Vec3::Zero();       // 1-sigma position uncertainty per world axis [m]
  bool gps_ok = false;                 // GPS fused within the last dropout timeout
  double since_gps_s = 0.0;            // time since the last fused GPS sample [s]
  bool valid = false;                  // initialised (attitude aligned, position known)
};

// Heading of body x, counter-clockwise from east [rad], in (-pi, pi].
inline double YawOf(const Quat& q) {
  const Vec3 x = q * Vec3::UnitX();
  return std::atan2(x.y(), x.x());
}

inline Quat QuatFromYaw(double yaw_rad) {
  return Quat(Eigen::AngleAxisd(yaw_rad, Vec3::UnitZ()));
}

inline double WrapPi(double a) {
  while (a > kPi) a -= 2.0 * kPi;
  while (a <= -kPi) a += 2.0 * kPi;
  return a;
}

}  // namespace swarmbox::flight
