// Holds the ODE multirotor model to physics. Each tolerance is stated and justified where used.
#include "swarmbox/physics/world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "test_util.hpp"

namespace swarmbox::physics {
namespace {

using testing::CalmWorld;
using testing::LoadShippedAirframe;
using testing::MakeWorld;
using testing::Spawn;

constexpr double kG = 9.80665;
constexpr double kDt = 0.001;  // default ODE sub-step [s]

Airframe DraglessX500() {
  Airframe af = LoadShippedAirframe("x500");
  af.body_drag_coefficient = {};
  af.motor.rotor_drag_coefficient = 0;
  af.motor.rolling_moment_coefficient = 0;
  return af;
}

void StepFor(World& w, double seconds) {
  const auto steps = static_cast<int>(std::lround(seconds / 0.004));
  for (int k = 0; k < steps; ++k) w.Step();
}

TEST(World, FreeFallMatchesHalfGTSquared) {
  auto world = MakeWorld(CalmWorld());
  const auto d = Spawn(*world, testing::MakeSpawn("d", DraglessX500(), Vec3{0, 0, 50}));
  const double z0 = world->Truth(d).position_m.z;
  for (int k = 1; k <= 500; ++k) {  // 2 s
    world->Step();
    const double t = world->time_s();
    const double z = world->Truth(d).position_m.z;
    // ODE integrates semi-implicitly (v += g dt; x += v dt), which falls exactly g t dt / 2
    // further than g t^2 / 2 after t: allow that bound plus 1% of it and 1 um.
    const double bound = kG * t * kDt / 2 * 1.01 + 1e-6;
    ASSERT_NEAR(z0 - z, kG * t * t / 2, bound) << "t=" << t;
    ASSERT_NEAR(world->Truth(d).velocity_m_s.z, -kG * t, 1e-9 + 1e-9 * t) << "t=" << t;
  }
}

TEST(World, BodyAtRestOnTheGroundStaysAtRest) {
  CollectingEventSink events;
  auto world = MakeWorld(CalmWorld());
  world->SetEventSink(&events);
  const auto d = Spawn(*world, testing::MakeSpawn("d", LoadShippedAirframe("x500"), Vec3{3, 4, 0}));
  const DroneTruth start = world->Truth(d);
  StepFor(*world, 10.0);
  const DroneTruth end = world->Truth(d);
  // Settling into ODE's 1 mm contact surface layer and the CFM compliance: a few mm at most.
  EXPECT_NEAR(end.position_m.z, start.position_m.z, 0.005);
  // Friction holds it: no horizontal creep beyond 0.1 mm in 10 s.
  EXPECT_NEAR(end.position_m.x, 3.0, 1e-4);
  EXPECT_NEAR(end.position_m.y, 4.0, 1e-4);
  EXPECT_LT(Norm(end.velocity_m_s), 1e-3);
  EXPECT_LT(Norm(end.body_rates_rad_s), 1e-3);
  EXPECT_TRUE(events.events.empty()) << EventName(events.events.front().kind);
}

TEST(World, AnalyticHoverSpeedHoldsAltitude) {
  auto world = MakeWorld(CalmWorld());
  const Airframe af = LoadShippedAirframe("x500");
  const double u = af.HoverRotorSpeed(0, kG) / af.motor.max_rot_velocity_rad_s;
  const auto d = Spawn(*world, testing::MakeSpawn("d", af, Vec3{0, 0, 10}, 0.0, u));
  const DroneTruth start = world->Truth(d);
  const std::vector<double> cmd(4, u);
  for (int k = 0; k < 2500; ++k) {  // 10 s
    ASSERT_TRUE(world->SetActuators(d, cmd).ok());
    world->Step();
  }
  const DroneTruth end = world->Truth(d);
  // Thrust equals weight up to rounding and the symmetric rotors cancel their torques, so only
  // floating-point residue drifts: 1 cm in 10 s is "tiny" (a real vehicle drifts metres).
  EXPECT_NEAR(end.position_m.z, start.position_m.z, 0.01);
  EXPECT_NEAR(end.position_m.x, 0.0, 0.01);
  EXPECT_NEAR(end.position_m.y, 0.0, 0.01);
  EXPECT_LT(Norm(end.velocity_m_s), 0.005);
  EXPECT_NEAR(end.attitude.w, 1.0, 1e-6);
}

TEST(World, HeavyLifterHoversWithItsStretcherAtTheCombinedHoverSpeed) {
  auto world = MakeWorld(CalmWorld());
  const Airframe af = LoadShippedAirframe("x8_heavy");
  const double u = af.HoverRotorSpeed(af.payloads[0].mass_kg, kG) / af.motor.max_rot_velocity_rad_s;
  const auto d = Spawn(*world, testing::MakeSpawn("lifter", af, Vec3{0, 0, 20}, 0.0, u, "stretcher", true));
  EXPECT_LT(u, 0.8);  // sized to hover loaded at ~70% throttle
  const double z0 = world->Truth(d).position_m.z;
  const std::vector<double> cmd(8, u);
  for (int k = 0; k < 1250; ++k) {  // 5 s
    ASSERT_TRUE(world->SetActuators(d, cmd).ok());
    world->Step();
  }
  // Same argument as the x500 hover: 1 cm in 5 s.
  EXPECT_NEAR(world->Truth(d).position_m.z, z0, 0.01);
  EXPECT_TRUE(world->Truth(d).payload_attached);
  EXPECT_LT(world->Truth(d).payload_swing_rad, 1e-3);
}

// omega(t) = w_max (1 - exp(-t / tau)) for a step from rest; 63.2% at t = tau.
void CheckMotorStep(const std::string& airframe) {
  auto world = MakeWorld(CalmWorld());
  const Airframe af = LoadShippedAirframe(airframe);
  const auto d = Spawn(*world, testing::MakeSpawn("d", af, Vec3{0, 0, 5}));
  world->SetPinned(d, true);
  const std::vector<double> full(af.rotors.size(), 1.0), off(af.rotors.size(), 0.0);
  ASSERT_TRUE(world->SetActuators(d, full).ok());
  const double tau = af.motor.time_constant_up_s, wmax = af.motor.max_rot_velocity_rad_s;
  double before = 0, after = 0;
  while (world->time_s() < 3 * tau) {
    world->Step();
    const double t = world->time_s();
    const double w = world->Truth(d).rotor_speed_rad_s[0];
    // The discrete update is the exact solution sampled every 1 ms: equal to 1e-9 relative.
    ASSERT_NEAR(w / wmax, 1 - std::exp(-t / tau), 1e-9) << "t=" << t;
    if (t <= tau) before = w / wmax;
    if (t > tau && after == 0) after = w / wmax;
  }
  // 63.2% is crossed between the control steps around tau.
  EXPECT_LT(before, 1 - std::exp(-1.0));
  EXPECT_GT(after, 1 - std::exp(-1.0));
  // Step down from the current speed: decays with the down time constant.
  const double w0 = world->Truth(d).rotor_speed_rad_s[0];
  const double t0 = world->time_s();
  ASSERT_TRUE(world->SetActuators(d, off).ok());
  const double tau_down = af.motor.time_constant_down_s;
  while (world->time_s() - t0 < 2 * tau_down) {
    world->Step();
    const double t = world->time_s() - t0;
    ASSERT_NEAR(world->Truth(d).rotor_speed_rad_s[0] / w0, std::exp(-t / tau_down), 1e-9) << "t=" << t;
  }
}

TEST(World, MotorStepReaches63PercentAtItsTimeConstant) {
  CheckMotorStep("x500");
  CheckMotorStep("x8_heavy");
}

TEST(World, YawTorqueFollowsSpinDirection) {
  auto world = MakeWorld(CalmWorld());
  const Airframe af = DraglessX500();
  const double u = af.HoverRotorSpeed() / af.motor.max_rot_velocity_rad_s;
  const auto d = Spawn(*world, testing::MakeSpawn("d", af, Vec3{0, 0, 20}, 0.0, u));
  // Speed up the ccw rotors (0, 1): their reaction torque turns the body clockwise (yaw rate < 0).
  const std::vector<double> cmd = {u * 1.05, u * 1.05, u * 0.95, u * 0.95};
  for (int k = 0; k < 50; ++k) {
    ASSERT_TRUE(world->SetActuators(d, cmd).ok());
    world->Step();
  }
  EXPECT_LT(world->Truth(d).body_rates_rad_s.z, -0.1);
  EXPECT_NEAR(world->Truth(d).body_rates_rad_s.x, 0.0, 1e-6);
}

TEST(World, ActuatorCountMismatchIsAnError) {
  auto world = MakeWorld(CalmWorld());
  const auto d = Spawn(*world, testing::MakeSpawn("d", LoadShippedAirframe("x500")));
  const std::vector<double> three(3, 0.5);
  const Status s = world->SetActuators(d, three);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().message(), "drone 'd' has 4 rotors, got 3 actuator values");
}

TEST(World, DuplicateDroneNameIsRejected) {
  auto world = MakeWorld(CalmWorld());
  Spawn(*world, testing::MakeSpawn("d", LoadShippedAirframe("x500")));
  auto again = world->AddDrone(testing::MakeSpawn("d", LoadShippedAirframe("x500"), Vec3{5, 0, 0}));
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(again.error().message(), "duplicate drone name 'd'");
}

TEST(World, FallFromHeightIsACrashAndKillsTheMotors) {
  CollectingEventSink events;
  auto world = MakeWorld(CalmWorld());
  world->SetEventSink(&events);
  const auto d = Spawn(*world, testing::MakeSpawn("d", DraglessX500(), Vec3{0, 0, 10}));
  StepFor(*world, 2.0);
  ASSERT_EQ(events.events.size(), 1u);
  const PhysicsEvent& e = events.events[0];
  EXPECT_EQ(e.kind, EventKind::kCrash);
  EXPECT_EQ(e.a, "d");
  EXPECT_EQ(e.b, "ground");
  // No drag: impact at sqrt(2 g h) = 14.0 m/s, seen at the sub-step before contact (+- g dt).
  EXPECT_NEAR(e.speed_m_s, std::sqrt(2 * kG * 10), 0.05);
  EXPECT_TRUE(world->Truth(d).crashed);
  EXPECT_EQ(e.ToLogEvent().str().rfind("t=1.4", 0), 0u) << e.ToLogEvent().str();
  EXPECT_NE(e.ToLogEvent().str().find("node=physics event=crash a=d b=ground speed="), std::string::npos);
}

TEST(World, ShortDropIsAHardLanding) {
  CollectingEventSink events;
  auto world = MakeWorld(CalmWorld());
  world->SetEventSink(&events);
  const auto d = Spawn(*world, testing::MakeSpawn("d", LoadShippedAirframe("x500"), Vec3{0, 0, 0.2}));
  StepFor(*world, 1.0);
  ASSERT_EQ(events.events.size(), 1u);
  EXPECT_EQ(events.events[0].kind, EventKind::kHardLanding);
  // sqrt(2 g 0.2) = 1.98 m/s: above 1.5 (hard landing), below 4 (crash).
  EXPECT_NEAR(events.events[0].speed_m_s, 1.98, 0.05);
  EXPECT_FALSE(world->Truth(d).crashed);
}

TEST(World, DroneDroneCollisionIsReportedOnceByTheLowerIndex) {
  CollectingEventSink events;
  auto world = MakeWorld(CalmWorld());
  world->SetEventSink(&events);
  const auto low = Spawn(*world, testing::MakeSpawn("low", LoadShippedAirframe("x500"), Vec3{0, 0, 5}));
  Spawn(*world, testing::MakeSpawn("high", LoadShippedAirframe("x500"), Vec3{0.1, 0, 6}));
  world->SetPinned(low, true);
  StepFor(*world, 1.0);
  ASSERT_GE(events.events.size(), 1u);
  EXPECT_EQ(events.events[0].kind, EventKind::kCollision);
  EXPECT_EQ(events.events[0].a, "low");
  EXPECT_EQ(events.events[0].b, "high");
  // falls 1 m less the box heights (0.3 m): ~sqrt(2 g 0.7) = 3.7 m/s.
  EXPECT_NEAR(events.events[0].speed_m_s, std::sqrt(2 * kG * 0.7), 0.3);
}

TEST(World, DroneObstacleCollisionNamesTheObstacle) {
  WorldConfig config = CalmWorld();
  config.obstacles.push_back({.id = "slab", .center_m = {0, 0, 1}, .size_m = {4, 4, 2}, .yaw_rad = 0});
  CollectingEventSink events;
  auto world = MakeWorld(config);
  world->SetEventSink(&events);
  Spawn(*world, testing::MakeSpawn("d", LoadShippedAirframe("x500"), Vec3{0, 0, 2.5}));
  StepFor(*world, 1.0);
  ASSERT_GE(events.events.size(), 1u);
  EXPECT_EQ(events.events[0].kind, EventKind::kCollision);
  EXPECT_EQ(events.events[0].b, "slab");
  EXPECT_NEAR(world->Truth(0).position_m.z, 2.0 + 0.23, 0.01);  // resting on the slab
}

TEST(World, GeofenceBreachIsReported) {
  WorldConfig config = CalmWorld();
  config.size_x_m = 10;
  config.size_y_m = 10;
  CollectingEventSink events;
  auto world = MakeWorld(config);
  world->SetEventSink(&events);
  Spawn(*world, testing::MakeSpawn("d", LoadShippedAirframe("x500"), Vec3{6, 0, 0}));
  world->Step();
  ASSERT_EQ(events.events.size(), 1u);
  EXPECT_EQ(events.events[0].kind, EventKind::kGeofence);
}

TEST(World, ExternalForceAcceleratesAsNewtonSays) {
  auto world = MakeWorld(CalmWorld());
  const Airframe af = DraglessX500();
  const double u = af.HoverRotorSpeed() / af.motor.max_rot_velocity_rad_s;
  const auto d = Spawn(*world, testing::MakeSpawn("d", af, Vec3{0, 0, 20}, 0, u));
  world->SetExternalForce(d, {af.mass_kg * 2.0, 0, 0});  // 2 m/s^2 east
  StepFor(*world, 1.0);
  // Level hover, no drag: v = a t exactly up to floating point.
  EXPECT_NEAR(world->Truth(d).velocity_m_s.x, 2.0, 1e-6);
  world->SetExternalForce(d, {});
  StepFor(*world, 0.5);
  EXPECT_NEAR(world->Truth(d).velocity_m_s.x, 2.0, 1e-6);
}

TEST(World, WindPushesADroneDownwind) {
  WorldConfig config = CalmWorld();
  config.wind.mean_m_s = {5, 0, 0};
  auto world = MakeWorld(config);
  const Airframe af = LoadShippedAirframe("x500");
  const double u = af.HoverRotorSpeed() / af.motor.max_rot_velocity_rad_s;
  const auto d = Spawn(*world, testing::MakeSpawn("d", af, Vec3{0, 0, 20}, 0.0, u));
  StepFor(*world, 1.0);
  EXPECT_GT(world->Truth(d).velocity_m_s.x, 0.3);
  EXPECT_NEAR(world->wind_m_s().x, 5.0, 1e-12);
}

}  // namespace
}  // namespace swarmbox::physics
