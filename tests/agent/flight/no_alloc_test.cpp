// STYLE.md 12: no allocation in the control loop. Counts operator new calls (this binary replaces
// the global operator new) while the flight controller runs 10 s of closed loop on a synthetic
// hovering sample stream, after the set-up has allocated what it needs.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/flight/flight_config.hpp"
#include "swarmbox/flight/flight_controller.hpp"
#include "swarmbox/flight/offboard_failsafe.hpp"

// The replacement operators below pair malloc with free; GCC 12 cannot see that through inlining
// (at -O1, the level of test sources, it reports -Wmismatched-new-delete).
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

namespace {
std::atomic<long> g_news{0};
}  // namespace

void* operator new(std::size_t n) {
  g_news.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace swarmbox::flight {
namespace {

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
payloads:
  - {name: box, mass_kg: 0.5, sling_length_m: 1.0, size_m: [0.3, 0.3, 0.2], hook_m: [0, 0, -0.1]}
)";

TEST(NoAllocation, ControlStepsAndSetpointsDoNotAllocate) {
  auto doc = yaml::Parse(kQuad, "quad.yaml");
  ASSERT_TRUE(doc.ok());
  auto cfg = ParseFlightConfig(*doc, "quad.yaml");
  ASSERT_TRUE(cfg.ok()) << cfg.error().ToString();
  auto fc = FlightController::Create(*cfg, {});  // swing damping (shaper buffer) allocated here
  ASSERT_TRUE(fc.ok()) << fc.error().ToString();
  SensorSample s;
  s.accel_m_s2 = Vec3(0.0, 0.0, kGravity_m_s2);
  s.mag_fresh = true;
  s.mag_body = Vec3(0.0, 0.21, -0.42);
  s.baro_fresh = true;
  s.gps_fresh = s.gps_valid = true;
  FlightEvent e;
  const long before = g_news.load();
  double sink = 0.0;
  int accepted = 0;
  for (int i = 0; i < 2500; ++i) {
    s.t_s = i * 0.004;
    s.gps_fresh = i % 25 == 0;
    sink += fc->Step(s).u[0];
    if (i == 500) accepted += fc->Command(Setpoint::Takeoff(5.0)) ? 1 : 0;
    if (i == 1500) accepted += fc->Command(Setpoint::Position(Vec3(3.0, 0.0, 5.0), 0.5)) ? 1 : 0;
    if (i == 2000) accepted += fc->Command(Setpoint::Land()) ? 1 : 0;
    while (fc->PopEvent(&e)) sink += e.t_s;
  }
  const long during = g_news.load() - before;
  EXPECT_EQ(during, 0) << "operator new called " << during << " times in 2500 control steps";
  EXPECT_EQ(accepted, 3);  // the steps really flew: take-off, position, land accepted
  EXPECT_TRUE(std::isfinite(sink));
}

// The trajectory kind streamed every 5th step (a brain at 50 Hz), with every axis rule and a yaw
// rate, and the offboard failsafe stepped alongside: neither allocates.
TEST(NoAllocation, TrajectoryStreamAndOffboardFailsafeDoNotAllocate) {
  auto doc = yaml::Parse(kQuad, "quad.yaml");
  ASSERT_TRUE(doc.ok());
  auto cfg = ParseFlightConfig(*doc, "quad.yaml");
  ASSERT_TRUE(cfg.ok()) << cfg.error().ToString();
  auto fc = FlightController::Create(*cfg, {});
  ASSERT_TRUE(fc.ok()) << fc.error().ToString();
  OffboardFailsafe failsafe(1.0, 5.0);
  SensorSample s;
  s.accel_m_s2 = Vec3(0.0, 0.0, kGravity_m_s2);
  s.mag_fresh = true;
  s.mag_body = Vec3(0.0, 0.21, -0.42);
  s.baro_fresh = true;
  s.gps_fresh = s.gps_valid = true;
  const double nan = std::nan("");
  TrajectoryTarget t;
  t.pos_m = Vec3(2.0, nan, nan);
  t.vel_m_s = Vec3(0.5, 1.0, nan);
  t.acc_m_s2 = Vec3(nan, nan, 0.2);
  t.yawspeed_rad_s = 0.3;
  FlightEvent e;
  OffboardFailsafe::Event fe;
  const long before = g_news.load();
  double sink = 0.0;
  int accepted = 0;
  for (int i = 0; i < 2500; ++i) {
    s.t_s = i * 0.004;
    s.gps_fresh = i % 25 == 0;
    sink += fc->Step(s).u[0];
    if (i == 500) accepted += fc->Command(Setpoint::Takeoff(5.0)) ? 1 : 0;
    if (i > 600 && i % 5 == 0) {
      if (i == 1500) t = TrajectoryTarget{};  // all unset: hold
      accepted += fc->Command(Setpoint::Trajectory(t)) ? 1 : 0;
    }
    const bool answered = i < 2000;
    sink += static_cast<double>(failsafe.Update(s.t_s, answered));
    while (fc->PopEvent(&e)) sink += e.t_s;
    while (failsafe.PopEvent(&fe)) sink += fe.silent_s;
  }
  const long during = g_news.load() - before;
  EXPECT_EQ(during, 0) << "operator new called " << during << " times in 2500 control steps";
  EXPECT_EQ(accepted, 1 + 379);  // take-off and every trajectory setpoint (steps 605..2495)
  EXPECT_EQ(fc->mode(), FlightMode::kTrajectory);
  EXPECT_EQ(failsafe.action(), OffboardFailsafe::Action::kHold);  // silent since 8 s: lost at 9 s
  EXPECT_TRUE(std::isfinite(sink));
}

}  // namespace
}  // namespace swarmbox::flight
