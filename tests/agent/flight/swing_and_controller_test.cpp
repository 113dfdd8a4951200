// Swing damping pieces (ZVD shaper, pendulum observer), the flight configuration reader and the
// flight controller's setpoint interface and modes.
#include <gtest/gtest.h>

#include <cmath>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/flight/flight_config.hpp"
#include "swarmbox/flight/flight_controller.hpp"
#include "swarmbox/flight/swing_damping.hpp"

namespace swarmbox::flight {
namespace {

TEST(InputShaper, ZvdImpulsesSumToOneAndDelayByOnePeriod) {
  InputShaper sh;
  sh.Configure(4.0, 0.0, 0.004);
  TrajectoryPoint zero;
  sh.Reset(zero);
  TrajectoryPoint step;
  step.pos_m = Vec3(1.0, 0.0, 0.0);
  std::vector<double> out;
  for (int i = 0; i < 1200; ++i) out.push_back(sh.Shape(step).pos_m.x());
  EXPECT_NEAR(out[0], 0.25, 1e-12);     // 1/(1+K)^2 with K = 1 (undamped)
  EXPECT_NEAR(out[600], 0.75, 1e-12);   // + 2K/(1+K)^2 after T/2
  EXPECT_NEAR(out[1100], 1.0, 1e-12);   // + K^2/(1+K)^2 after T
  EXPECT_NEAR(sh.delay_s(), 4.0, 1e-9);
}

TEST(SwingObserver, MeasuresTheSlingAngleFromTheCablePullOnTheImu) {
  SwingObserver obs;
  obs.Configure(4.0, 120.0);
  // Payload of 80 kg hanging 10 deg east of the hook, drone level and still: the cable pulls the
  // drone east and down; the accelerometer's body x reads the horizontal pull / drone mass.
  const double th = 10.0 * kPi / 180.0;
  const double t = 80.0 * kGravity_m_s2;  // quasi-static tension
  const Vec3 f_body(t * std::sin(th) / 120.0, 0.0, kGravity_m_s2);
  for (int i = 0; i < 500; ++i) obs.Update(f_body, Quat::Identity(), Vec3::Zero(), 80.0, 0.004);
  EXPECT_NEAR(obs.measured_swing().x(), std::sin(th), 1e-9);
  for (int i = 0; i < 10000; ++i) obs.Update(f_body, Quat::Identity(), Vec3::Zero(), 80.0, 0.004);
  EXPECT_NEAR(obs.swing_angle_rad(), th, 0.005);
  // A steady lean is not a swing: no damping push once it has settled (40 s here).
  EXPECT_LT(obs.DampingAcceleration(1.0).norm(), 0.02);
}

TEST(SwingObserver, RestsWithoutAPayload) {
  SwingObserver obs;
  obs.Configure(4.0, 120.0);
  obs.Update(Vec3(1.0, 0.0, kGravity_m_s2), Quat::Identity(), Vec3::Zero(), 0.0, 0.004);
  EXPECT_EQ(obs.DampingAcceleration(1.0).norm(), 0.0);
}

constexpr const char* kQuad = R"(
name: testquad
mass_kg: 2.0
inertia_kg_m2: [0.0217, 0.0217, 0.04]
collision: {box_m: [0.5, 0.5, 0.2]}
base_height_m: 0.2
motor: {motor_constant: 8.54858e-06, moment_constant: 0.016, max_rot_velocity_rad_s: 1000.0,
        time_constant_up_s: 0.0125, time_constant_down_s: 0.025}
rotors:
  - {position_m: [0.174, -0.174, 0.06], direction: ccw}
  - {position_m: [-0.174, 0.174, 0.06], direction: ccw}
  - {position_m: [0.174, 0.174, 0.06], direction: cw}
  - {position_m: [-0.174, -0.174, 0.06], direction: cw}
control:
  position: {xy_p: 1.1, vel_xy_pid: [2.0, 0.5, 0.1], tilt_max_deg: 35}
  rate: {roll_pid: [0.2, 0.3, 0.004]}
)";

TEST(FlightConfig, ReadsGeometryAndControlBlock) {
  auto doc = yaml::Parse(kQuad, "quad.yaml");
  ASSERT_TRUE(doc.ok());
  auto cfg = ParseFlightConfig(*doc, "quad.yaml");
  ASSERT_TRUE(cfg.ok()) << cfg.error().ToString();
  EXPECT_EQ(cfg->rotors.size(), 4u);
  EXPECT_EQ(cfg->rotors[2].spin_dir, -1);
  EXPECT_DOUBLE_EQ(cfg->position.xy_p, 1.1);
  EXPECT_DOUBLE_EQ(cfg->position.vel_i.x(), 0.5);
  EXPECT_NEAR(cfg->position.tilt_max_rad, 35.0 * kPi / 180.0, 1e-12);
  EXPECT_DOUBLE_EQ(cfg->rate.p.x(), 0.2);
  EXPECT_DOUBLE_EQ(cfg->rate.p.y(), 0.15);  // untouched: PX4 default
  EXPECT_DOUBLE_EQ(cfg->base_height_m, 0.2);
}

TEST(FlightConfig, UnknownControlKeyIsAnErrorWithItsPlace) {
  std::string text = std::string(kQuad) + "  lqr: {q: 1}\n";
  auto doc = yaml::Parse(text, "quad.yaml");
  ASSERT_TRUE(doc.ok());
  auto cfg = ParseFlightConfig(*doc, "quad.yaml");
  ASSERT_FALSE(cfg.ok());
  EXPECT_NE(cfg.error().ToString().find("lqr"), std::string::npos) << cfg.error().ToString();
  EXPECT_NE(cfg.error().ToString().find("quad.yaml:"), std::string::npos) << cfg.error().ToString();
}

TEST(FlightController, RejectsSetpointsTheModeCannotTakeAndReportsThem) {
  auto doc = yaml::Parse(kQuad, "quad.yaml");
  ASSERT_TRUE(doc.ok());
  auto cfg = ParseFlightConfig(*doc, "quad.yaml");
  ASSERT_TRUE(cfg.ok());
  auto fc = FlightController::Create(*cfg, {});
  ASSERT_TRUE(fc.ok()) << fc.error().ToString();
  EXPECT_FALSE(fc->Command(Setpoint::Takeoff(5.0)));  // estimator not aligned yet
  SensorSample s;
  s.accel_m_s2 = Vec3(0.0, 0.0, kGravity_m_s2);
  s.mag_fresh = true;
  s.mag_body = Vec3(0.0, 0.21, -0.42);
  s.gps_fresh = s.gps_valid = true;
  for (int i = 0; i <= 300; ++i) {
    s.t_s = i * 0.004;
    const ActuatorOutput& out = fc->Step(s);
    EXPECT_FALSE(out.armed);  // motors off on the ground
  }
  ASSERT_EQ(fc->mode(), FlightMode::kIdle);
  EXPECT_FALSE(fc->Command(Setpoint::Position(Vec3(1, 0, 5), 0.0)));  // on the ground
  EXPECT_FALSE(fc->Command(Setpoint::Takeoff(std::nan(""))));
  EXPECT_TRUE(fc->Command(Setpoint::Takeoff(5.0)));
  EXPECT_EQ(fc->mode(), FlightMode::kTakeoff);
  EXPECT_FALSE(fc->Command(Setpoint::Takeoff(5.0)));  // already flying
  s.t_s += 0.004;
  EXPECT_TRUE(fc->Step(s).armed);
  int rejected = 0, ready = 0, takeoff = 0;
  FlightEvent e;
  while (fc->PopEvent(&e)) {
    rejected += e.kind == FlightEventKind::kRejected;
    ready += e.kind == FlightEventKind::kReady;
    takeoff += e.kind == FlightEventKind::kTakeoff;
  }
  EXPECT_EQ(rejected, 4);
  EXPECT_EQ(ready, 1);
  EXPECT_EQ(takeoff, 1);
}

TEST(FlightController, RefusesAnAirframeThatCannotLiftItsLoad) {
  auto doc = yaml::Parse(kQuad, "quad.yaml");
  ASSERT_TRUE(doc.ok());
  auto cfg = ParseFlightConfig(*doc, "quad.yaml");
  ASSERT_TRUE(cfg.ok());
  ControllerOptions o;
  o.payload_mass_kg = 50.0;
  auto fc = FlightController::Create(*cfg, o);
  ASSERT_FALSE(fc.ok());
  EXPECT_NE(fc.error().message().find("cannot hover"), std::string::npos) << fc.error().message();
}

}  // namespace
}  // namespace swarmbox::flight
