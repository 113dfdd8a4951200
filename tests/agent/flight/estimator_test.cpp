// Estimator against a synthetic vehicle (a test double of the sensors: exact kinematics plus
// seeded Gaussian noise; the GPS delayed by 0.12 s with a constant offset and white noise, as
// the physics server's receiver model over a short test), so each behaviour is checked in
// isolation from the physics library.
#include "swarmbox/flight/estimator.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <random>

namespace swarmbox::flight {
namespace {

const Vec3 kMagWorld(0.0, 0.21, -0.42);

// A vehicle moving with a given world acceleration and attitude; produces sensor samples at
// 250 Hz (IMU), 50 Hz (baro), 100 Hz (mag), 10 Hz (GPS).
class FakeVehicle {
 public:
  explicit FakeVehicle(unsigned seed) : rng_(seed) {}
  Vec3 pos = Vec3(0.0, 0.0, 0.2);
  Vec3 vel = Vec3::Zero();
  Quat att = Quat::Identity();
  Vec3 acc = Vec3::Zero();
  Vec3 rate = Vec3::Zero();     // body [rad/s]
  bool gps_on = true;
  double gps_noise = 0.2;                      // white, per fix [m]
  double gps_noise_v = 0.5;
  double eph = 0.0, epv = 0.0;                 // reported accuracy (0: none)
  Vec3 gps_offset = Vec3(0.6, -0.4, 1.0);      // the receiver's slowly varying error [m]
  static constexpr int kDelaySteps = 30;       // 0.12 s at 250 Hz
  int k = 0;

  SensorSample Step(double dt) {
    ++k;
    pos += vel * dt + 0.5 * acc * dt * dt;
    vel += acc * dt;
    att = (att * Quat(Eigen::AngleAxisd(rate.norm() * dt, rate.norm() > 0 ? Vec3(rate.normalized()) : Vec3::UnitX()))).normalized();
    SensorSample s;
    s.t_s = k * dt;
    s.imu_fresh = true;
    s.accel_m_s2 = att.inverse() * (acc + Vec3(0.0, 0.0, kGravity_m_s2)) + Noise(0.02);
    s.gyro_rad_s = rate + Vec3(0.003, -0.002, 0.001) + Noise(0.002);  // with a constant bias
    s.baro_fresh = k % 5 == 0;
    s.baro_alt_m = pos.z() + 488.0 + N(0.12);
    s.mag_fresh = k % 3 == 0;
    s.mag_body = att.inverse() * kMagWorld + Noise(0.005);
    past_pos_[static_cast<std::size_t>(k) % past_pos_.size()] = pos;
    past_vel_[static_cast<std::size_t>(k) % past_vel_.size()] = vel;
    const std::size_t then = static_cast<std::size_t>(std::max(1, k - kDelaySteps)) % past_pos_.size();
    s.gps_fresh = k % 25 == 0;
    s.gps_valid = gps_on;
    s.gps_pos_m = past_pos_[then] + gps_offset + Vec3(N(gps_noise), N(gps_noise), N(gps_noise_v));
    s.gps_eph_m = eph;
    s.gps_epv_m = epv;
    s.gps_vel_m_s = past_vel_[then] + Noise(0.1);
    return s;
  }
  // Moves the truth (and its recent history) by d: a jump the estimator cannot see coming.
  void Shift(const Vec3& d) {
    pos += d;
    for (Vec3& p : past_pos_) p += d;
  }

 private:
  double N(double sd) { return std::normal_distribution<double>(0.0, sd)(rng_); }
  Vec3 Noise(double sd) { return Vec3(N(sd), N(sd), N(sd)); }
  std::mt19937 rng_;
  std::array<Vec3, 64> past_pos_{};
  std::array<Vec3, 64> past_vel_{};
};

EstimatorParams KnownStart(const Vec3& p) {
  EstimatorParams e;
  e.has_initial_pos = true;
  e.initial_pos_m = p;
  return e;
}

TEST(Estimator, AlignsTiltAndHeadingFromAccelerometerAndMagnetometer) {
  FakeVehicle v(1);
  v.att = Quat(Eigen::AngleAxisd(1.0, Vec3::UnitZ()) * Eigen::AngleAxisd(0.1, Vec3::UnitX()));
  Estimator est(KnownStart(v.pos));
  for (int i = 0; i < 2500; ++i) est.Update(v.Step(0.004));
  ASSERT_TRUE(est.state().valid);
  EXPECT_LT(est.state().att.angularDistance(v.att), 0.02);  // < 1.2 deg after 10 s
  EXPECT_NEAR(YawOf(est.state().att), 1.0, 0.02);
  EXPECT_NEAR(est.gyro_bias().x(), 0.003, 0.0015);          // bias learnt
}

TEST(Estimator, TracksAnAcceleratingVehicleWithoutTiltingTheAttitude) {
  FakeVehicle v(2);
  Estimator est(KnownStart(v.pos));
  for (int i = 0; i < 1250; ++i) est.Update(v.Step(0.004));
  // 3 s of 2 m/s^2 east (attitude held level by the double: the tilt reference must use the
  // GPS-derived acceleration, not assume hover).
  v.acc = Vec3(2.0, 0.0, 0.0);
  double worst_tilt = 0.0;
  for (int i = 0; i < 750; ++i) {
    est.Update(v.Step(0.004));
    worst_tilt = std::max(worst_tilt, est.state().att.angularDistance(v.att));
  }
  v.acc.setZero();
  for (int i = 0; i < 500; ++i) est.Update(v.Step(0.004));
  // Without the GPS-derived reference the filter would lean ~0.09 rad towards level here.
  EXPECT_LT(worst_tilt, 0.06);                                      // < 3.4 deg
  EXPECT_LT((est.state().vel_m_s - v.vel).norm(), 0.15);            // 6 m/s, within 0.15
  EXPECT_LT((est.state().pos_m - v.pos).head<2>().norm(), 0.5);
}

TEST(Estimator, DeadReckonsThroughGpsDropoutWithGrowingUncertaintyAndGlidesBack) {
  FakeVehicle v(3);
  Estimator est(KnownStart(v.pos));
  est.SetAtRest(true);  // 5 s on the ground first, as before a take-off: the biases are learnt
  for (int i = 0; i < 1250; ++i) est.Update(v.Step(0.004));
  est.SetAtRest(false);
  for (int i = 0; i < 3750; ++i) est.Update(v.Step(0.004));
  const double std_before = est.state().pos_std_m.x();
  ASSERT_TRUE(est.state().gps_ok);
  v.gps_on = false;
  for (int i = 0; i < 1250; ++i) est.Update(v.Step(0.004));  // 5 s
  EXPECT_FALSE(est.state().gps_ok);
  EXPECT_GT(est.state().pos_std_m.x(), 2.0 * std_before);    // uncertainty grows
  EXPECT_LT((est.state().pos_m - v.pos).norm(), 1.0);        // drift bounded
  // Recovery: move the truth 1 m away from the estimate (a drifted dead reckoning); the estimate
  // must glide back at the slew limit, not jump.
  v.Shift(Vec3(1.0, 0.0, 0.0));
  v.gps_on = true;
  Vec3 last = est.state().pos_m;
  double max_rate = 0.0, max_speed = 0.0;
  for (int i = 0; i < 2500; ++i) {
    est.Update(v.Step(0.004));
    // The vehicle stands still: whatever the estimated position does is the correction gliding
    // in (1 m/s per axis) on top of the estimated velocity (itself gliding, < 0.5 m/s here).
    // Horizontal only: z also takes the (ungated, centimetre) barometer corrections.
    max_rate = std::max(max_rate, (est.state().pos_m - last).head<2>().norm() / 0.004);
    max_speed = std::max(max_speed, est.state().vel_m_s.norm());
    last = est.state().pos_m;
  }
  EXPECT_TRUE(est.state().gps_ok);
  EXPECT_LT(max_rate, 1.5 * std::sqrt(2.0));  // a glide: a jump of 1 m in one step is 250 m/s
  EXPECT_LT(max_speed, 1.5);                   // the estimate does not race off
  EXPECT_LT((est.state().pos_m - v.pos).norm(), 0.3);
}

TEST(Estimator, BarometerOffsetIsAnchoredAtTheKnownStart) {
  FakeVehicle v(4);
  Estimator est(KnownStart(v.pos));
  for (int i = 0; i < 2500; ++i) est.Update(v.Step(0.004));
  EXPECT_NEAR(est.state().pos_m.z(), v.pos.z(), 0.1);  // baro reads 488 m AMSL, estimate is ENU
}

// A standalone receiver reporting the accuracy the estimator was configured with (the
// airframe's) is fused exactly as one that reports nothing.
TEST(Estimator, ReportingTheAirframesAccuracyChangesNothing) {
  FakeVehicle quiet(5), reporting(5);
  reporting.eph = 0.8;  // EstimatorParams' gps_pos_h_std_m / gps_pos_v_std_m
  reporting.epv = 1.5;
  Estimator a(KnownStart(quiet.pos)), b(KnownStart(reporting.pos));
  for (int i = 0; i < 5000; ++i) {
    const double t = i * 0.004;
    quiet.acc = reporting.acc = Vec3(std::sin(0.5 * t), std::cos(0.3 * t), 0.2 * std::sin(t));
    a.Update(quiet.Step(0.004));
    b.Update(reporting.Step(0.004));
  }
  EXPECT_EQ(a.state().pos_m, b.state().pos_m);
  EXPECT_EQ(a.state().vel_m_s, b.state().vel_m_s);
  EXPECT_EQ(a.state().pos_std_m, b.state().pos_std_m);
}

// An RTK-fixed receiver (5 mm per fix, reporting 1 cm) is trusted to its reported accuracy: with
// the report the estimate follows it to the centimetre; without it (the 0.2 m fix-to-fix noise a
// standalone receiver has) several times worse on the same samples.
TEST(Estimator, TrustsAnRtkFixToItsReportedAccuracy) {
  const auto rms_error = [](double eph, double epv, Vec3* pos_std) {
    FakeVehicle v(6);
    v.gps_noise = 0.005;
    v.gps_noise_v = 0.008;
    v.gps_offset = Vec3(0.004, -0.003, 0.006);
    v.eph = eph;
    v.epv = epv;
    Estimator est(KnownStart(v.pos));
    est.SetAtRest(true);
    for (int i = 0; i < 1250; ++i) est.Update(v.Step(0.004));
    est.SetAtRest(false);
    double sum2 = 0.0;
    int n = 0;
    for (int i = 0; i < 7500; ++i) {  // 30 s of manoeuvres
      const double t = i * 0.004;
      v.acc = Vec3(1.5 * std::sin(0.7 * t), 1.0 * std::cos(0.4 * t), 0.5 * std::sin(0.9 * t));
      est.Update(v.Step(0.004));
      if (i >= 1250) {
        sum2 += (est.state().pos_m - v.pos).squaredNorm();
        ++n;
      }
    }
    *pos_std = est.state().pos_std_m;
    return std::sqrt(sum2 / n);
  };
  Vec3 std_rtk, std_plain;
  const double rtk = rms_error(0.0093, 0.0163, &std_rtk);
  const double plain = rms_error(0.0, 0.0, &std_plain);
  std::printf("rtk fix: reported rms_m=%.4f, unreported rms_m=%.4f\n", rtk, plain);
  EXPECT_LT(rtk, 0.03);
  EXPECT_LT(3.0 * rtk, plain);
  EXPECT_LT(std_rtk.x(), 0.5 * std_plain.x());  // and it knows it
}

}  // namespace
}  // namespace swarmbox::flight
