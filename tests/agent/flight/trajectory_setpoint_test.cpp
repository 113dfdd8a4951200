// The trajectory setpoint kind (PX4 TrajectorySetpoint, NaN = unset; setpoint.hpp): the position
// controller's per-axis control (pure), and the flight controller's handling of the kind on a
// synthetic sensor stream (the drone does not move: what is checked is what each axis is asked
// for). Flown in closed loop: trajectory_closed_loop_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/flight/flight_config.hpp"
#include "swarmbox/flight/flight_controller.hpp"
#include "swarmbox/flight/position_control.hpp"

namespace swarmbox::flight {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

StateEstimate Hovering() {
  StateEstimate s;
  s.valid = true;
  s.pos_m = Vec3(0.0, 0.0, 5.0);
  return s;
}

PositionControl Controller() {
  PositionControl pc;
  PositionParams p;
  p.thrust_min_n = 2.0;
  p.thrust_max_n = 40.0;
  pc.SetParams(p);
  return pc;
}

// ---- PositionControl, per axis --------------------------------------------------------------

TEST(PositionControlAxes, VelocityAxisIgnoresThePositionAndTracksTheVelocity) {
  PositionControl pc = Controller();
  PositionSetpoint sp;
  sp.axes = {AxisControl::kVelocity, AxisControl::kPosition, AxisControl::kPosition};
  sp.pos_m = Vec3(100.0, 0.0, 5.0);  // x far away: must not matter on a velocity axis
  sp.vel_m_s = Vec3(1.0, 0.0, 0.0);
  const PositionOutput out = pc.Update(Hovering(), sp, 2.0, 0.004);
  ASSERT_TRUE(out.valid);
  EXPECT_DOUBLE_EQ(out.vel_sp_m_s.x(), 1.0);
  EXPECT_DOUBLE_EQ(out.vel_sp_m_s.y(), 0.0);
  EXPECT_NEAR(out.acc_sp_m_s2.x(), pc.params().vel_p.x() * 1.0, 1e-9);  // P on 1 m/s
}

TEST(PositionControlAxes, PositionAxisAddsTheVelocityFeedForward) {
  PositionControl pc = Controller();
  PositionSetpoint sp;
  sp.pos_m = Vec3(1.0, 0.0, 5.0);
  sp.vel_m_s = Vec3(0.5, 0.0, 0.0);
  const PositionOutput out = pc.Update(Hovering(), sp, 2.0, 0.004);
  ASSERT_TRUE(out.valid);
  EXPECT_NEAR(out.vel_sp_m_s.x(), 0.5 + pc.params().xy_p * 1.0, 1e-12);
}

TEST(PositionControlAxes, AccelerationAxisTakesTheFeedForwardAloneAndFreezesItsIntegral) {
  PositionControl pc = Controller();
  PositionSetpoint sp;
  sp.axes = {AxisControl::kPosition, AxisControl::kPosition, AxisControl::kAcceleration};
  sp.pos_m = Vec3(0.0, 0.0, 50.0);  // z far up: ignored, the axis flies on acceleration alone
  sp.vel_m_s = Vec3(0.0, 0.0, 3.0);
  sp.acc_m_s2 = Vec3(0.0, 0.0, 1.5);
  StateEstimate s = Hovering();
  s.vel_m_s = Vec3(0.0, 0.0, -1.0);      // a velocity error the velocity loop would act on
  s.accel_m_s2 = Vec3(0.0, 0.0, 0.7);    // and a D term
  for (int i = 0; i < 250; ++i) {
    const PositionOutput out = pc.Update(s, sp, 2.0, 0.004);
    ASSERT_TRUE(out.valid);
    EXPECT_NEAR(out.thrust_world_n.z(), 2.0 * (1.5 + kGravity_m_s2), 1e-9);
    EXPECT_TRUE(std::isnan(out.vel_sp_m_s.z()));
    EXPECT_DOUBLE_EQ(out.acc_sp_m_s2.z(), 1.5);
  }
  EXPECT_EQ(pc.integral().z(), 0.0);  // frozen
}

TEST(PositionControlAxes, HorizontalAccelerationOnlyLeansTheWayAsked) {
  PositionControl pc = Controller();
  PositionSetpoint sp;
  sp.axes = {AxisControl::kAcceleration, AxisControl::kPosition, AxisControl::kPosition};
  sp.pos_m = Vec3(-30.0, 0.0, 5.0);
  sp.acc_m_s2 = Vec3(2.0, 0.0, 0.0);
  const PositionOutput out = pc.Update(Hovering(), sp, 2.0, 0.004);
  ASSERT_TRUE(out.valid);
  EXPECT_NEAR(out.thrust_world_n.x(), 2.0 * 2.0, 1e-9);
  EXPECT_NEAR(out.thrust_world_n.z(), 2.0 * kGravity_m_s2, 1e-9);
  EXPECT_EQ(pc.integral().x(), 0.0);
}

TEST(PositionControlAxes, VelocityCapsTightenTheParamsLimits) {
  PositionControl pc = Controller();
  PositionSetpoint sp;
  sp.pos_m = Vec3(100.0, 0.0, 100.0);
  sp.vel_cap_xy_m_s = 2.0;
  sp.vel_cap_up_m_s = 1.0;
  const PositionOutput out = pc.Update(Hovering(), sp, 2.0, 0.004);
  EXPECT_NEAR(out.vel_sp_m_s.x(), 2.0, 1e-12);
  EXPECT_NEAR(out.vel_sp_m_s.z(), 1.0, 1e-12);
  sp.pos_m = Vec3(0.0, 0.0, -100.0);
  sp.vel_cap_down_m_s = 0.5;
  EXPECT_NEAR(pc.Update(Hovering(), sp, 2.0, 0.004).vel_sp_m_s.z(), -0.5, 1e-12);
}

// ---- Setpoint::FromTrajectory ----------------------------------------------------------------

TEST(SetpointFromTrajectory, PurePositionAndPureVelocityKeepTheirSmoothedKinds) {
  TrajectoryTarget t;
  t.pos_m = Vec3(1.0, 2.0, 3.0);
  t.yaw_rad = 0.5;
  Setpoint sp = Setpoint::FromTrajectory(t);
  EXPECT_EQ(sp.kind, Setpoint::Kind::kPosition);
  EXPECT_EQ(sp.value, Vec3(1.0, 2.0, 3.0));
  EXPECT_EQ(sp.yaw_rad, 0.5);
  TrajectoryTarget v;
  v.vel_m_s = Vec3(1.0, 0.0, 0.0);
  sp = Setpoint::FromTrajectory(v);
  EXPECT_EQ(sp.kind, Setpoint::Kind::kVelocity);
  EXPECT_TRUE(std::isnan(sp.yaw_rad));  // heading kept
  // Anything else stays a trajectory: a feed-forward, a partial position, a yaw rate.
  TrajectoryTarget ff = t;
  ff.vel_m_s = Vec3(1.0, 0.0, 0.0);
  EXPECT_EQ(Setpoint::FromTrajectory(ff).kind, Setpoint::Kind::kTrajectory);
  TrajectoryTarget partial;
  partial.pos_m = Vec3(1.0, 2.0, kNan);
  EXPECT_EQ(Setpoint::FromTrajectory(partial).kind, Setpoint::Kind::kTrajectory);
  TrajectoryTarget spin = t;
  spin.yaw_rad = kNan;
  spin.yawspeed_rad_s = 0.3;
  EXPECT_EQ(Setpoint::FromTrajectory(spin).kind, Setpoint::Kind::kTrajectory);
  EXPECT_EQ(Setpoint::FromTrajectory(TrajectoryTarget{}).kind, Setpoint::Kind::kTrajectory);
  const Setpoint tr = Setpoint::Trajectory(spin);
  EXPECT_EQ(tr.trajectory.yawspeed_rad_s, 0.3);
  EXPECT_TRUE(std::isnan(tr.yaw_rad));
}

// ---- FlightController on a synthetic stream --------------------------------------------------

constexpr const char* kQuad = R"(
name: testquad
mass_kg: 2.0
base_height_m: 0.0
inertia_kg_m2: [0.0217, 0.0217, 0.04]
collision: {box_m: [0.5, 0.5, 0.2]}
motor: {motor_constant: 8.54858e-06, moment_constant: 0.016, max_rot_velocity_rad_s: 1000.0,
        time_constant_up_s: 0.0125, time_constant_down_s: 0.025}
rotors:
  - {position_m: [0.174, -0.174, 0.06], direction: ccw}
  - {position_m: [-0.174, 0.174, 0.06], direction: ccw}
  - {position_m: [0.174, 0.174, 0.06], direction: cw}
  - {position_m: [-0.174, -0.174, 0.06], direction: cw}
)";

// A controller whose estimator has aligned on a still sample stream at the origin; Step() goes on
// feeding the same samples (the estimate stays put: the setpoints are what is looked at).
class TrajectoryKind : public ::testing::Test {
 protected:
  void SetUp() override {
    auto doc = yaml::Parse(kQuad, "quad.yaml");
    ASSERT_TRUE(doc.ok());
    auto cfg = ParseFlightConfig(*doc, "quad.yaml");
    ASSERT_TRUE(cfg.ok()) << cfg.error().ToString();
    auto fc = FlightController::Create(*cfg, {});
    ASSERT_TRUE(fc.ok()) << fc.error().ToString();
    fc_ = std::make_unique<FlightController>(std::move(*fc));
    s_.accel_m_s2 = Vec3(0.0, 0.0, kGravity_m_s2);
    s_.mag_fresh = true;
    s_.mag_body = Vec3(0.0, 0.21, -0.42);
    s_.baro_fresh = true;
    s_.gps_fresh = s_.gps_valid = true;
    Steps(300);
    ASSERT_EQ(fc_->mode(), FlightMode::kIdle);
  }
  void Steps(int n) {
    for (int i = 0; i < n; ++i) {
      s_.t_s += 0.004;
      fc_->Step(s_);
    }
  }
  int Count(FlightEventKind kind) {
    int n = 0;
    FlightEvent e;
    while (fc_->PopEvent(&e)) n += e.kind == kind;
    return n;
  }
  void Airborne() {
    ASSERT_TRUE(fc_->Command(Setpoint::Takeoff(5.0)));
    Steps(10);
  }
  const PositionOutput& Pos() const { return fc_->telemetry().position; }
  double YawSp() const { return YawOf(Pos().att_sp); }

  std::unique_ptr<FlightController> fc_;
  SensorSample s_;
};

TEST_F(TrajectoryKind, RejectedOnTheGroundAsTheOtherKinds) {
  TrajectoryTarget t;
  t.pos_m = Vec3(1.0, 0.0, 5.0);
  Count(FlightEventKind::kRejected);
  EXPECT_FALSE(fc_->Command(Setpoint::Trajectory(t)));  // idle: not armed
  EXPECT_FALSE(fc_->Command(Setpoint::Position(t.pos_m, 0.0)));
  EXPECT_EQ(Count(FlightEventKind::kRejected), 2);
  EXPECT_EQ(fc_->mode(), FlightMode::kIdle);
  Steps(5);
  EXPECT_FALSE(fc_->Step(s_).armed);
}

TEST_F(TrajectoryKind, AcceptedInTheAirAsItsOwnModeNamedTrajectory) {
  Airborne();
  TrajectoryTarget t;
  t.pos_m = Vec3(3.0, 0.0, 5.0);
  EXPECT_TRUE(fc_->Command(Setpoint::Trajectory(t)));
  EXPECT_EQ(fc_->mode(), FlightMode::kTrajectory);
  EXPECT_EQ(FlightModeName(FlightMode::kTrajectory), "trajectory");
  Steps(1);
  EXPECT_TRUE(fc_->Step(s_).armed);
  // Infinity is not "unset": rejected, the mode and target unchanged.
  TrajectoryTarget bad = t;
  bad.vel_m_s.z() = std::numeric_limits<double>::infinity();
  Count(FlightEventKind::kRejected);
  EXPECT_FALSE(fc_->Command(Setpoint::Trajectory(bad)));
  TrajectoryTarget bad_yaw;
  bad_yaw.yawspeed_rad_s = -std::numeric_limits<double>::infinity();
  EXPECT_FALSE(fc_->Command(Setpoint::Trajectory(bad_yaw)));
  EXPECT_EQ(Count(FlightEventKind::kRejected), 2);
  Steps(1);
  EXPECT_EQ(fc_->mode(), FlightMode::kTrajectory);
  EXPECT_EQ(fc_->telemetry().reference.pos_m.x(), 3.0);
}

TEST_F(TrajectoryKind, PositionAxesGoToThePositionWithTheVelocityFeedForwardAtTheLimits) {
  Airborne();
  const Vec3 here = fc_->estimate().pos_m;
  TrajectoryTarget t;
  t.pos_m = here + Vec3(1.0, -0.5, 0.2);
  t.vel_m_s = Vec3(0.25, kNan, kNan);  // x feeds forward; y, z: 0
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(t)));
  Steps(1);
  const Vec3 err = t.pos_m - fc_->estimate().pos_m;
  const Vec3 v = Pos().vel_sp_m_s;
  EXPECT_NEAR(v.x(), 0.25 + fc_->config().position.xy_p * err.x(), 1e-9);
  EXPECT_NEAR(v.y(), fc_->config().position.xy_p * err.y(), 1e-9);
  EXPECT_NEAR(v.z(), fc_->config().position.z_p * err.z(), 1e-9);
  // Far away: the velocity within the airframe's limits (not the 1.2x the position loop may chase
  // a moving reference with).
  t.pos_m = here + Vec3(300.0, 400.0, 100.0);
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(t)));
  Steps(1);
  EXPECT_NEAR(Pos().vel_sp_m_s.head<2>().norm(), fc_->config().limits.vel_max_xy_m_s, 1e-9);
  EXPECT_NEAR(Pos().vel_sp_m_s.z(), fc_->config().limits.vel_max_up_m_s, 1e-9);
}

TEST_F(TrajectoryKind, VelocityAxesTrackTheVelocityWithinTheLimits) {
  Airborne();
  TrajectoryTarget t;
  t.vel_m_s = Vec3(1.0, -2.0, -0.5);
  t.acc_m_s2 = Vec3(0.3, kNan, kNan);
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(t)));
  Steps(1);
  EXPECT_NEAR(Pos().vel_sp_m_s.x(), 1.0, 1e-12);
  EXPECT_NEAR(Pos().vel_sp_m_s.y(), -2.0, 1e-12);
  EXPECT_NEAR(Pos().vel_sp_m_s.z(), -0.5, 1e-12);
  EXPECT_EQ(fc_->telemetry().reference.acc_m_s2.x(), 0.3);
  EXPECT_EQ(fc_->telemetry().reference.acc_m_s2.y(), 0.0);
  // Beyond the limits: horizontal scaled along its direction, vertical clamped.
  t.vel_m_s = Vec3(30.0, 40.0, -9.0);
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(t)));
  Steps(1);
  const double vmax = fc_->config().limits.vel_max_xy_m_s;
  EXPECT_NEAR(Pos().vel_sp_m_s.x(), 0.6 * vmax, 1e-9);
  EXPECT_NEAR(Pos().vel_sp_m_s.y(), 0.8 * vmax, 1e-9);
  EXPECT_NEAR(Pos().vel_sp_m_s.z(), -fc_->config().limits.vel_max_down_m_s, 1e-9);
}

TEST_F(TrajectoryKind, AccelerationOnlyAxesHaveNoVelocityLoop) {
  Airborne();
  const Vec3 here = fc_->estimate().pos_m;
  TrajectoryTarget t;
  t.pos_m = Vec3(kNan, here.y(), here.z());  // y, z held at where it is: thrust to spare
  t.acc_m_s2 = Vec3(1.5, kNan, kNan);
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(t)));
  Steps(1);
  EXPECT_TRUE(std::isnan(Pos().vel_sp_m_s.x()));
  EXPECT_FALSE(std::isnan(Pos().vel_sp_m_s.y()));
  // What the position loop asked for on x: the acceleration, within the tilt (not limiting here).
  EXPECT_NEAR(Pos().acc_sp_m_s2.x(), 1.5, 1e-9);
}

TEST_F(TrajectoryKind, MixedAxesXyPositionZVelocity) {
  Airborne();
  const Vec3 here = fc_->estimate().pos_m;
  TrajectoryTarget t;
  t.pos_m = Vec3(here.x() + 2.0, here.y(), kNan);
  t.vel_m_s = Vec3(kNan, kNan, 0.8);
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(t)));
  Steps(1);
  const Vec3 err = t.pos_m - fc_->estimate().pos_m;
  EXPECT_NEAR(Pos().vel_sp_m_s.x(), fc_->config().position.xy_p * err.x(), 1e-9);
  EXPECT_NEAR(Pos().vel_sp_m_s.z(), 0.8, 1e-12);  // z: the velocity, whatever the height
}

TEST_F(TrajectoryKind, AllUnsetHoldsEachAxisAtItsLatchedPoint) {
  Airborne();
  const Vec3 here = fc_->estimate().pos_m;
  TrajectoryTarget hold;  // NaN everywhere
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(hold)));
  Steps(1);
  // At rest, the braking point is where it is.
  EXPECT_NEAR((fc_->telemetry().reference.pos_m - here).norm(), 0.0, 0.05);
  const Vec3 latched = fc_->telemetry().reference.pos_m;
  // The same "all unset" streamed again keeps the latched point.
  for (int i = 0; i < 20; ++i) {
    ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(hold)));
    Steps(5);
    EXPECT_EQ(fc_->telemetry().reference.pos_m, latched);
  }
  // One axis leaves the hold (velocity on x), the others stay at their points.
  TrajectoryTarget vx;
  vx.vel_m_s.x() = 1.0;
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(vx)));
  Steps(1);
  EXPECT_NEAR(Pos().vel_sp_m_s.x(), 1.0, 1e-12);
  EXPECT_EQ(fc_->telemetry().reference.pos_m.y(), latched.y());
  EXPECT_EQ(fc_->telemetry().reference.pos_m.z(), latched.z());
}

TEST_F(TrajectoryKind, AHeldAxisLatchesWhereBrakingEnds) {
  Airborne();
  // The drone is moving east at 3 m/s (the estimate follows GPS and the accelerometer: fake
  // both by feeding a moving fix for a while).
  for (int i = 0; i < 500; ++i) {
    s_.t_s += 0.004;
    s_.gps_pos_m = Vec3(3.0 * (s_.t_s - 1.2), 0.0, 0.0);
    s_.gps_vel_m_s = Vec3(3.0, 0.0, 0.0);
    s_.gps_fresh = i % 25 == 0;
    fc_->Step(s_);
  }
  const StateEstimate e = fc_->estimate();
  ASSERT_GT(e.vel_m_s.x(), 1.0);
  TrajectoryTarget hold;
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(hold)));
  const double a = fc_->config().limits.acc_max_xy_m_s2;
  const double expect_x = e.pos_m.x() + e.vel_m_s.x() * std::abs(e.vel_m_s.x()) / (2.0 * a);
  s_.gps_fresh = false;
  fc_->Step(s_);
  EXPECT_NEAR(fc_->telemetry().reference.pos_m.x(), expect_x, 1e-9);
}

TEST_F(TrajectoryKind, YawSetsTheHeadingYawspeedTurnsItAndNeitherKeepsIt) {
  Airborne();
  TrajectoryTarget t;
  t.pos_m = fc_->estimate().pos_m;
  t.yaw_rad = 1.0;
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(t)));
  Steps(1);
  EXPECT_NEAR(YawSp(), 1.0, 1e-9);
  // Yawspeed: the heading setpoint turns at that rate, 0.5 rad/s for 1 s (250 steps of 4 ms).
  t.yaw_rad = kNan;
  t.yawspeed_rad_s = 0.5;
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(t)));
  Steps(250);
  EXPECT_NEAR(YawSp(), 1.5, 1e-6);
  // Neither: kept.
  t.yawspeed_rad_s = kNan;
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(t)));
  Steps(100);
  EXPECT_NEAR(YawSp(), 1.5, 1e-6);
  // A rate beyond the limit turns at the limit (1.5 rad/s), through +-pi.
  t.yawspeed_rad_s = -10.0;
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(t)));
  Steps(1000);  // 4 s: -6 rad
  EXPECT_NEAR(YawSp(), WrapPi(1.5 - 6.0), 1e-6);
}

TEST_F(TrajectoryKind, OtherKindsAfterATrajectoryStartFromWhereTheDroneIs) {
  Airborne();
  TrajectoryTarget t;
  t.vel_m_s = Vec3(2.0, 0.0, 0.0);
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(t)));
  Steps(100);
  ASSERT_TRUE(fc_->Command(Setpoint::Hold()));
  EXPECT_EQ(fc_->mode(), FlightMode::kHold);
  Steps(1);
  // The reference restarted at the estimate (not where take-off had left it).
  EXPECT_NEAR((fc_->telemetry().reference.pos_m - fc_->estimate().pos_m).norm(), 0.0, 0.05);
  ASSERT_TRUE(fc_->Command(Setpoint::Trajectory(t)));
  ASSERT_TRUE(fc_->Command(Setpoint::Land()));
  EXPECT_EQ(fc_->mode(), FlightMode::kLand);
}

}  // namespace
}  // namespace swarmbox::flight
