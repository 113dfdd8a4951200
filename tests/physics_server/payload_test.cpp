// The x8_heavy's slung stretcher: pendulum physics, attach and release.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "test_util.hpp"

namespace swarmbox::physics {
namespace {

using testing::CalmWorld;
using testing::LoadShippedAirframe;
using testing::MakeWorld;
using testing::Spawn;

constexpr double kG = 9.80665;

TEST(Payload, SmallAngleSwingPeriodIsTwoPiSqrtLOverG) {
  auto world = MakeWorld(CalmWorld());
  const Airframe af = LoadShippedAirframe("x8_heavy");
  const auto d = Spawn(*world, testing::MakeSpawn("lifter", af, Vec3{0, 0, 20}, 0.0, 0.0, "stretcher", true));
  world->SetPinned(d, true);  // a fixed hook: the pendulum alone
  // The loaded stretcher (80 kg; the airframe's is the empty one): the push below stays small-angle.
  ASSERT_TRUE(world->ReleasePayload(d).ok());
  ASSERT_TRUE(world->AttachPayload(d, 80.0).ok());
  // Excite a small swing across the stretcher (about its long axis) with a 0.5 s northerly push
  // of wind, then calm.
  WindConfig gust;
  gust.mean_m_s = {0, 8, 0};
  world->SetWind(gust);
  for (int k = 0; k < 125; ++k) world->Step();
  world->SetWind(WindConfig{});
  const double hook_y = world->Truth(d).position_m.y;
  std::vector<double> crossings;  // times the payload crosses under the hook, moving north
  double prev = world->Truth(d).payload_position_m.y - hook_y, max_swing = 0;
  double prev_t = world->time_s();
  while (world->time_s() < 25.0) {
    world->Step();
    const double y = world->Truth(d).payload_position_m.y - hook_y;
    max_swing = std::max(max_swing, world->Truth(d).payload_swing_rad);
    if (prev < 0 && y >= 0) crossings.push_back(prev_t + (world->time_s() - prev_t) * (-prev) / (y - prev));
    prev = y;
    prev_t = world->time_s();
  }
  ASSERT_GE(crossings.size(), 4u);
  const double period = (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  const double length = af.payloads[0].sling_length_m;
  const double expected = 2 * std::numbers::pi * std::sqrt(length / kG);
  // The brief's tolerance, 2%: a rigid stretcher swinging about its long axis is a physical
  // pendulum, I = m L^2 + I_cm with I_cm / (m L^2) = 0.2%, i.e. +0.1% on the period.
  EXPECT_NEAR(period, expected, 0.02 * expected) << "period " << period << " s, expected " << expected;
  EXPECT_LT(max_swing, 0.1);   // small-angle regime (< 6 deg)
  EXPECT_GT(max_swing, 0.002); // and it did swing
}

TEST(Payload, AttachNeedsTheHookAtSlingLengthAndReleaseDropsIt) {
  CollectingEventSink events;
  auto world = MakeWorld(CalmWorld());
  world->SetEventSink(&events);
  const Airframe af = LoadShippedAirframe("x8_heavy");
  const auto d = Spawn(*world, testing::MakeSpawn("lifter", af, Vec3{0, 0, 0}, 0.0, 0.0, "stretcher"));
  EXPECT_FALSE(world->Truth(d).payload_attached);
  // On the ground beside the lifter: the hook is far too close to the stretcher for a 4 m sling.
  const Status too_close = world->AttachPayload(d);
  ASSERT_FALSE(too_close.ok());
  EXPECT_NE(too_close.error().message().find("lifter': hook is"), std::string::npos) << too_close.error().message();
  EXPECT_NE(too_close.error().message().find("from the stretcher, needs 4.00 +- 0.50 m"), std::string::npos)
      << too_close.error().message();

  // A lifter spawned with the stretcher hanging: release it and it falls away.
  const auto h = Spawn(*world, testing::MakeSpawn("hauler", af, Vec3{30, 0, 15}, 0.0, 0.0, "stretcher", true));
  EXPECT_TRUE(world->Truth(h).payload_attached);
  ASSERT_TRUE(world->ReleasePayload(h).ok());
  EXPECT_FALSE(world->Truth(h).payload_attached);
  const Status again = world->ReleasePayload(h);
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(again.error().message(), "drone 'hauler' carries no attached payload");
  const double z0 = world->Truth(h).payload_position_m.z;
  for (int k = 0; k < 100; ++k) world->Step();
  // Free fall for 0.4 s: g t^2 / 2 = 0.78 m (its drag at < 4 m/s takes < 1% off).
  EXPECT_NEAR(world->Truth(h).payload_position_m.z, z0 - 0.5 * 9.80665 * 0.16, 0.02);

  ASSERT_GE(events.events.size(), 1u);
  EXPECT_EQ(events.events[0].kind, EventKind::kPayloadReleased);
  EXPECT_EQ(events.events[0].a, "hauler");
  EXPECT_EQ(events.events[0].b, "stretcher");
}

TEST(Payload, AttachWithinToleranceCreatesTheSling) {
  CollectingEventSink events;
  auto world = MakeWorld(CalmWorld());
  world->SetEventSink(&events);
  const Airframe af = LoadShippedAirframe("x8_heavy");
  const auto d = Spawn(*world, testing::MakeSpawn("lifter", af, Vec3{0, 0, 20}, 0.0, 0.0, "stretcher", true));
  ASSERT_TRUE(world->ReleasePayload(d).ok());
  ASSERT_TRUE(world->AttachPayload(d).ok());  // still exactly at sling length
  EXPECT_TRUE(world->Truth(d).payload_attached);
  ASSERT_EQ(events.events.size(), 2u);
  EXPECT_EQ(events.events[1].kind, EventKind::kPayloadAttached);
  EXPECT_EQ(events.events[1].ToLogEvent().str(), "t=0.000 node=physics event=payload_attached a=lifter b=stretcher");
}

// Vertical speed [m/s] of the x8_heavy after 1 s of free flight with its rotors at the speed that
// hovers the airframe plus `hover_for_kg`, its stretcher re-attached with AttachPayload(attach_kg).
double VerticalSpeedAfterOneSecond(double attach_kg, double hover_for_kg) {
  auto world = MakeWorld(CalmWorld());
  const Airframe af = LoadShippedAirframe("x8_heavy");
  const double u = af.HoverRotorSpeed(hover_for_kg) / af.motor.max_rot_velocity_rad_s;
  const auto d = Spawn(*world, testing::MakeSpawn("lifter", af, Vec3{0, 0, 20}, 0.0, u, "stretcher", true));
  world->SetPinned(d, true);
  EXPECT_TRUE(world->ReleasePayload(d).ok());
  EXPECT_TRUE(world->AttachPayload(d, attach_kg).ok());  // still at sling length: no fall yet
  const std::vector<double> throttle(af.rotors.size(), u);
  EXPECT_TRUE(world->SetActuators(d, throttle).ok());
  for (int k = 0; k < 250; ++k) world->Step();  // 1 s pinned: rotors at speed, stretcher at rest
  world->SetPinned(d, false);
  for (int k = 0; k < 250; ++k) world->Step();
  return world->Truth(d).velocity_m_s.z;
}

TEST(Payload, AttachWithAMassSetsWhatTheLifterCarries) {
  // Given rotors sized to hover the lifter with 15 kg below, when the stretcher is attached as
  // 15 kg, then the lifter holds its height; attached as 80 kg it sinks at
  // a = 65 kg g / 215 kg ~ 3 m/s^2.
  const double with_15 = VerticalSpeedAfterOneSecond(15.0, 15.0);
  const double with_80 = VerticalSpeedAfterOneSecond(80.0, 15.0);
  EXPECT_NEAR(with_15, 0.0, 0.3) << "15 kg attached, thrust for 15 kg";
  EXPECT_LT(with_80, -2.0) << "80 kg attached, thrust for 15 kg";
  EXPECT_GT(with_80, -4.0);
  // mass 0 keeps the airframe's (the empty stretcher's): hovers on the thrust for that.
  const double spawn_kg = LoadShippedAirframe("x8_heavy").payloads[0].mass_kg;
  EXPECT_NEAR(VerticalSpeedAfterOneSecond(0.0, spawn_kg), 0.0, 0.3) << "mass kept";
  EXPECT_GT(VerticalSpeedAfterOneSecond(0.0, spawn_kg + 40.0), 1.0) << "mass kept, thrust for 40 kg more";
}

TEST(Payload, AttachRefusesANegativeOrNanMass) {
  auto world = MakeWorld(CalmWorld());
  const auto d = Spawn(*world, testing::MakeSpawn("lifter", LoadShippedAirframe("x8_heavy"), Vec3{0, 0, 20}, 0.0, 0.0,
                                                  "stretcher", true));
  ASSERT_TRUE(world->ReleasePayload(d).ok());
  for (double bad : {-1.0, std::nan("")}) {
    const Status s = world->AttachPayload(d, bad);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(s.error().message().find("payload mass must be >= 0 kg"), std::string::npos) << s.error().message();
    EXPECT_FALSE(world->Truth(d).payload_attached);
  }
}

TEST(Payload, SpawningAttachedTooLowIsRefused) {
  auto world = MakeWorld(CalmWorld());
  auto r = world->AddDrone(testing::MakeSpawn("lifter", LoadShippedAirframe("x8_heavy"), Vec3{0, 0, 1}, 0.0, 0.0, "stretcher", true));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message().find("too low to spawn with the stretcher hanging"), std::string::npos)
      << r.error().message();
}

TEST(Payload, UnknownPayloadIsRefused) {
  auto world = MakeWorld(CalmWorld());
  auto r = world->AddDrone(testing::MakeSpawn("s", LoadShippedAirframe("x500"), Vec3{}, 0.0, 0.0, "stretcher"));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message(), "drone 's': airframe x500 has no payload 'stretcher'");
}

// Where a released stretcher came to rest: drops it from a lifter pinned 6 m up at (x, 0) and
// steps until event=payload_at_rest (at most 15 s). The events seen after the release.
std::vector<PhysicsEvent> DropStretcher(const WorldConfig& config, double x_m) {
  CollectingEventSink events;
  auto world = MakeWorld(config);
  world->SetEventSink(&events);
  const auto d = Spawn(*world, testing::MakeSpawn("lifter", LoadShippedAirframe("x8_heavy"), Vec3{x_m, 0, 6}, 0.0, 0.0,
                                                  "stretcher", true));
  world->SetPinned(d, true);
  EXPECT_TRUE(world->ReleasePayload(d).ok());
  events.events.clear();
  while (world->time_s() < 15.0 && events.events.empty()) world->Step();
  for (int k = 0; k < 500; ++k) world->Step();  // 2 s more: reported once
  return events.events;
}

TEST(Payload, AReleasedStretcherOnFlatGroundIsReportedAtRestLevelOnce) {
  const std::vector<PhysicsEvent> events = DropStretcher(CalmWorld(), 3.0);
  ASSERT_EQ(events.size(), 1u);
  const PhysicsEvent& e = events[0];
  EXPECT_EQ(e.kind, EventKind::kPayloadAtRest);
  EXPECT_EQ(e.a, "lifter");
  EXPECT_NEAR(e.position_m.x, 3.0, 0.1);
  EXPECT_NEAR(e.position_m.y, 0.0, 0.1);
  EXPECT_NEAR(e.position_m.z, 0.25 / 2, 0.02);  // the stretcher's half height
  EXPECT_LT(e.tilt_deg, 1.0);
  // Fallen ~1.5 m (0.55 s), then still for 1 s.
  EXPECT_GT(e.t_s, 1.5);
  EXPECT_LT(e.t_s, 5.0);
  const std::string line = e.ToLogEvent().str();
  EXPECT_NE(line.find(" node=physics event=payload_at_rest drone=lifter x=3.00 y="), std::string::npos) << line;
  EXPECT_NE(line.find(" z=0.12 tilt_deg=0.0"), std::string::npos) << line;
}

TEST(Payload, AStretcherReleasedOverABoxEdgeIsReportedTiltedOrRaised) {
  // A 1 m high box whose west edge is at x = 0; the stretcher (2 m along x) is dropped centred
  // 0.2 m inside it: it lands across the edge (and stays on the box top, z = 1.12: measured).
  WorldConfig config = CalmWorld();
  config.obstacles.push_back({"block", {1.0, 0, 0.5}, {2.0, 3.0, 1.0}, 0.0, ObstacleKind::kBox});
  const std::vector<PhysicsEvent> events = DropStretcher(config, 0.2);
  ASSERT_EQ(events.size(), 1u);
  const PhysicsEvent& e = events[0];
  EXPECT_EQ(e.kind, EventKind::kPayloadAtRest);
  EXPECT_TRUE(e.tilt_deg > 5.0 || e.position_m.z > 0.5) << e.ToLogEvent().str();
}

TEST(Payload, AStretcherPickedUpAgainBeforeItSettlesIsNotReported) {
  CollectingEventSink events;
  auto world = MakeWorld(CalmWorld());
  world->SetEventSink(&events);
  const auto d = Spawn(*world, testing::MakeSpawn("lifter", LoadShippedAirframe("x8_heavy"), Vec3{0, 0, 20}, 0.0, 0.0,
                                                  "stretcher", true));
  world->SetPinned(d, true);
  ASSERT_TRUE(world->ReleasePayload(d).ok());
  ASSERT_TRUE(world->AttachPayload(d).ok());  // still at sling length, hanging still
  for (int k = 0; k < 750; ++k) world->Step();
  for (const PhysicsEvent& e : events.events) EXPECT_NE(e.kind, EventKind::kPayloadAtRest);
}

}  // namespace
}  // namespace swarmbox::physics
