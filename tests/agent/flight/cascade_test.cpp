// The cascade's pure pieces: attitude P, rate PID anti-windup, position control with tilt limit,
// and the smooth trajectory. Tolerances are stated per check.
#include <gtest/gtest.h>

#include <cmath>

#include "swarmbox/flight/attitude_control.hpp"
#include "swarmbox/flight/position_control.hpp"
#include "swarmbox/flight/rate_control.hpp"
#include "swarmbox/flight/trajectory.hpp"

namespace swarmbox::flight {
namespace {

Quat RollPitchYaw(double roll, double pitch, double yaw) {
  return Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
              Eigen::AngleAxisd(roll, Vec3::UnitX()));
}

TEST(AttitudeControl, SmallRollErrorGivesProportionalRollRate) {
  AttitudeControl ac;
  ac.SetGains({});
  const Vec3 rate = ac.Update(Quat::Identity(), RollPitchYaw(0.05, 0.0, 0.0), 0.0);
  EXPECT_NEAR(rate.x(), 6.5 * 0.05, 1e-3);  // P * error, small angle (0.1 % error)
  EXPECT_NEAR(rate.y(), 0.0, 1e-9);
  EXPECT_NEAR(rate.z(), 0.0, 1e-9);
}

TEST(AttitudeControl, SmallYawErrorUsesYawGain) {
  AttitudeControl ac;
  ac.SetGains({});
  const Vec3 rate = ac.Update(Quat::Identity(), RollPitchYaw(0.0, 0.0, 0.1), 0.0);
  EXPECT_NEAR(rate.z(), 2.8 * 0.1, 2e-3);  // yaw_P on the full error for small errors
}

TEST(AttitudeControl, LargeYawErrorDoesNotDisturbTiltAndRespectsRateLimit) {
  AttitudeControl ac;
  ac.SetGains({});
  const Vec3 rate = ac.Update(Quat::Identity(), RollPitchYaw(0.0, 0.0, 3.0), 0.0);
  EXPECT_NEAR(rate.x(), 0.0, 1e-9);
  EXPECT_NEAR(rate.y(), 0.0, 1e-9);
  EXPECT_GT(rate.z(), 0.0);
  EXPECT_LE(rate.z(), 200.0 * kPi / 180.0 + 1e-9);
}

TEST(RateControl, IntegratorStopsIntoSaturatedDirection) {
  RateControl rc;
  rc.SetGains({});
  for (int i = 0; i < 100; ++i) rc.Update(Vec3::Zero(), Vec3(1.0, 0.0, 0.0), Vec3::Zero(), 0.004, false);
  const double before = rc.integral().x();
  EXPECT_GT(before, 0.0);
  rc.SetSaturation({true, false, false}, {false, false, false});
  for (int i = 0; i < 100; ++i) rc.Update(Vec3::Zero(), Vec3(1.0, 0.0, 0.0), Vec3::Zero(), 0.004, false);
  EXPECT_DOUBLE_EQ(rc.integral().x(), before);
  // The other direction still integrates (unwinding is always allowed).
  for (int i = 0; i < 10; ++i) rc.Update(Vec3::Zero(), Vec3(-1.0, 0.0, 0.0), Vec3::Zero(), 0.004, false);
  EXPECT_LT(rc.integral().x(), before);
}

TEST(RateControl, IntegratorIsBoundedAndFrozenWhenLanded) {
  RateControl rc;
  rc.SetGains({});
  for (int i = 0; i < 100000; ++i) rc.Update(Vec3::Zero(), Vec3(0.5, 0.5, 0.5), Vec3::Zero(), 0.004, false);
  EXPECT_NEAR(rc.integral().x(), 0.3, 1e-12);
  rc.ResetIntegral();
  for (int i = 0; i < 100; ++i) rc.Update(Vec3::Zero(), Vec3(0.5, 0.5, 0.5), Vec3::Zero(), 0.004, true);
  EXPECT_EQ(rc.integral().norm(), 0.0);
}

TEST(RateControl, DTermActsOnMeasuredAngularAcceleration) {
  RateControl rc;
  rc.SetGains({});
  const Vec3 out = rc.Update(Vec3::Zero(), Vec3::Zero(), Vec3(10.0, 0.0, 0.0), 0.004, true);
  EXPECT_NEAR(out.x(), -0.003 * 10.0, 1e-12);
}

StateEstimate Hovering() {
  StateEstimate s;
  s.valid = true;
  s.pos_m = Vec3(0.0, 0.0, 5.0);
  return s;
}

TEST(PositionControl, HoverAtSetpointAsksForWeight) {
  PositionControl pc;
  PositionParams p;
  p.thrust_min_n = 2.0;
  p.thrust_max_n = 30.0;
  pc.SetParams(p);
  PositionSetpoint sp;
  sp.pos_m = Vec3(0.0, 0.0, 5.0);
  const PositionOutput out = pc.Update(Hovering(), sp, 2.0, 0.004);
  ASSERT_TRUE(out.valid);
  EXPECT_NEAR(out.thrust_n, 2.0 * kGravity_m_s2, 1e-9);
  EXPECT_NEAR(out.att_sp.angularDistance(Quat::Identity()), 0.0, 1e-9);
}

TEST(PositionControl, TiltIsLimitedAndAltitudeKeepsPriority) {
  PositionControl pc;
  PositionParams p;
  p.thrust_min_n = 2.0;
  p.thrust_max_n = 30.0;
  p.tilt_max_rad = 30.0 * kPi / 180.0;
  pc.SetParams(p);
  PositionSetpoint sp;
  sp.pos_m = Vec3(100.0, 0.0, 5.0);  // far east: wants a large horizontal acceleration
  const PositionOutput out = pc.Update(Hovering(), sp, 2.0, 0.004);
  ASSERT_TRUE(out.valid);
  const Vec3 z = out.att_sp * Vec3::UnitZ();
  EXPECT_NEAR(std::acos(z.z()), 30.0 * kPi / 180.0, 1e-6);  // at the limit, not beyond
  EXPECT_GT(z.x(), 0.0);                                    // leaning east
  EXPECT_NEAR(out.thrust_world_n.z(), 2.0 * kGravity_m_s2, 1e-9);  // vertical untouched
  EXPECT_NEAR(out.vel_sp_m_s.x(), p.vel_max_xy_m_s, 1e-9);  // velocity limit
}

TEST(PositionControl, NonFiniteInputIsRejected) {
  PositionControl pc;
  PositionSetpoint sp;
  sp.pos_m = Vec3(std::nan(""), 0.0, 0.0);
  EXPECT_FALSE(pc.Update(Hovering(), sp, 2.0, 0.004).valid);
}

TEST(PositionControl, AttitudeFromThrustKeepsYaw) {
  const Quat q = AttitudeFromThrustAndYaw(Vec3(0.1, 0.2, 1.0), 1.0);
  const Vec3 x = q * Vec3::UnitX();
  EXPECT_NEAR(std::atan2(x.y(), x.x()), 1.0, 1e-9);
  EXPECT_NEAR((q * Vec3::UnitZ() - Vec3(0.1, 0.2, 1.0).normalized()).norm(), 0.0, 1e-9);
}

TEST(Trajectory, PositionStepRespectsLimitsAndArrivesWithoutOvershoot) {
  TrajectoryLimits lim;
  Trajectory tr(lim);
  tr.Reset(Vec3::Zero(), Vec3::Zero());
  tr.SetPositionTarget(Vec3(10.0, 0.0, 0.0));
  double max_v = 0.0, max_a = 0.0, max_x = 0.0, t_arrive = -1.0;
  for (int k = 1; k <= 2500; ++k) {
    const TrajectoryPoint p = tr.Step(0.004);
    max_v = std::max(max_v, p.vel_m_s.norm());
    max_a = std::max(max_a, p.acc_m_s2.norm());
    max_x = std::max(max_x, p.pos_m.x());
    if (t_arrive < 0 && std::abs(p.pos_m.x() - 10.0) < 0.01) t_arrive = k * 0.004;
  }
  EXPECT_LE(max_v, lim.vel_max_xy_m_s + 1e-9);
  EXPECT_LE(max_a, lim.acc_max_xy_m_s2 + 1e-9);
  EXPECT_LE(max_x, 10.0 + 1e-6);  // no overshoot
  ASSERT_GT(t_arrive, 0.0);
  EXPECT_LT(t_arrive, 5.0);  // 10 m at 3 m/s^2 and 5 m/s: ~4 s
}

TEST(Trajectory, ClimbUsesVerticalLimits) {
  TrajectoryLimits lim;
  Trajectory tr(lim);
  tr.Reset(Vec3::Zero(), Vec3::Zero());
  tr.SetPositionTarget(Vec3(0.0, 0.0, -20.0));
  double min_vz = 0.0;
  for (int k = 0; k < 5000; ++k) min_vz = std::min(min_vz, tr.Step(0.004).vel_m_s.z());
  EXPECT_NEAR(min_vz, -lim.vel_max_down_m_s, 1e-9);
  EXPECT_TRUE(tr.Settled());
}

TEST(Trajectory, VelocityTargetRampsAtAccelerationLimit) {
  Trajectory tr;
  tr.Reset(Vec3::Zero(), Vec3::Zero());
  tr.SetVelocityTarget(Vec3(3.0, 0.0, 0.0));
  const TrajectoryPoint p = tr.Step(0.1);
  EXPECT_NEAR(p.vel_m_s.x(), 0.3, 1e-9);  // 3 m/s^2 * 0.1 s
  for (int k = 0; k < 100; ++k) tr.Step(0.1);
  EXPECT_NEAR(tr.reference().vel_m_s.x(), 3.0, 1e-9);
}

}  // namespace
}  // namespace swarmbox::flight
