// swarm::Flocking driving the x500 in closed loop, as the SAR brain drives a scout (agent/app
// sar_brain.cpp DriveFlock): every 0.1 s mission tick the flocking step runs on the flight stack's
// estimate and its velocity goes to the flight controller as a velocity setpoint (v_flock and
// v_max at the 7 m/s cruise speed); the physics library's x500 with seeded sensor noise, lockstep
// at 250 Hz (sim_harness.hpp).
//
// The case that matters for the camera: a lawnmower lane ends half a footprint (11.6 m at 30 m)
// inside the geofence, inside the wall's shill zone (flocking.hpp WallStandoffM, 12.45 m), so the
// shill agent brakes every lane end. Until 2026-11-28 its friction rule fed the drone's measured
// velocity back with gain c_shill 2, and that loop through the flight stack's lag swung the
// x500's pitch +-20-28 deg at ~1.4 Hz over the last 15-30 m of every lane toward a wall
// (rubble20: the camera, fixed to the body, looked up to 14 m fore and aft of the lane, and the
// people near the field's ends went unseen 27-45 % of the time against 2-6 % inside). The
// velocity part is now a limit on the command (flocking.cpp WallLimit).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "sim_harness.hpp"
#include "swarmbox/swarm/flocking.hpp"

namespace swarmbox::flight::testing {
namespace {

constexpr double kCruise_m_s = 7.0;  // MissionTuning::scout_cruise_m_s
constexpr int kTickSteps = 25;       // 0.1 s mission tick at the 250 Hz lockstep
constexpr double kTick_s = 0.1;

double TiltDeg(const Rig& r) {
  const auto q = r.truth().attitude;
  const Quat att(q.w, q.x, q.y, q.z);
  const Vec3 up = att * Vec3::UnitZ();
  return std::acos(std::clamp(up.z(), -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
}

TEST(FlockingClosedLoop, BrakingAtALaneEndNearTheGeofenceKeepsTheCameraLevel) {
  RigOptions o;
  o.seed = 42;
  auto rig = Rig::Create(o);
  ASSERT_TRUE(rig.ok()) << rig.error().ToString();
  Rig& r = **rig;
  ASSERT_TRUE(r.RunUntilMode(FlightMode::kIdle, 3.0));
  r.Run(5.0);
  ASSERT_TRUE(r.fc().Command(Setpoint::Takeoff(10.0)));
  ASSERT_TRUE(r.RunUntilMode(FlightMode::kHold, 40.0));
  r.Run(2.0);
  const Vec3 start = r.fc().estimate().pos_m;
  // A wall 70 m east; the lane's end 11.6 m short of it (half the x500's 23.2 m along-track
  // footprint at 30 m), at the height the drone holds.
  swarm::FlockingParams params;
  params.v_flock_m_s = kCruise_m_s;
  params.v_max_m_s = kCruise_m_s;
  const swarm::Geofence fence{start.x() - 200, start.x() + 70, start.y() - 200, start.y() + 200};
  swarm::Flocking flock(params, fence, {});
  const Vec3 goal(fence.max_x_m - 11.6, start.y(), start.z());
  flock.Reset(r.fc().estimate().vel_m_s);
  int step = 0;
  double max_speed = 0, peak_tilt_approach = 0, peak_tilt_braking = 0, max_x = -1e9;
  int tilt_reversals = 0;
  double peak_pitch_rate = 0;
  double last_pitch_rate_sign = 0;
  r.Run(30.0, {}, [&] {
    if (step++ % kTickSteps == 0) {
      const StateEstimate& s = r.fc().estimate();
      swarm::FlockingInput in;
      in.position_m = s.pos_m;
      in.velocity_m_s = s.vel_m_s;
      in.goal_m = goal;
      const swarm::FlockingOutput f = flock.Step(in, kTick_s);
      EXPECT_TRUE(r.fc().Command(Setpoint::Velocity(f.velocity_m_s, 0.0)));
    }
    const auto p = r.truth().position_m;
    const auto v = r.truth().velocity_m_s;
    max_x = std::max(max_x, p.x);
    max_speed = std::max(max_speed, std::hypot(v.x, v.y));
    // Braking: from where the shill engages at the cruise speed (WallStandoffM and the braking
    // curve put it ~30 m out at 5 m/s) to the end of the lane; before it, the climb-out from the
    // hover and the cruise.
    const bool braking = fence.max_x_m - p.x <= 32.0;
    double& peak_tilt = braking ? peak_tilt_braking : peak_tilt_approach;
    peak_tilt = std::max(peak_tilt, TiltDeg(r));
    // Fast pitch-rate sign changes while braking (above 1 rad/s, beyond a hover's jitter): a
    // swinging attitude reverses every half period.
    const double q = r.truth().body_rates_rad_s.y;
    if (braking) peak_pitch_rate = std::max(peak_pitch_rate, std::abs(q));
    if (braking && std::abs(q) > 1.0) {
      const double sign = q > 0 ? 1.0 : -1.0;
      if (last_pitch_rate_sign != 0 && sign != last_pitch_rate_sign) ++tilt_reversals;
      last_pitch_rate_sign = sign;
    }
  });
  const double end_gap = (goal.head<2>() - r.fc().estimate().pos_m.head<2>()).norm();
  std::printf(
      "flocking_wall max_speed_m_s=%.2f peak_tilt_approach_deg=%.1f peak_tilt_braking_deg=%.1f "
      "fast_pitch_reversals=%d peak_pitch_rate_rad_s=%.2f closest_to_wall_m=%.2f end_gap_m=%.2f\n",
      max_speed, peak_tilt_approach, peak_tilt_braking, tilt_reversals, peak_pitch_rate, fence.max_x_m - max_x,
      end_gap);
  EXPECT_FALSE(r.crashed());
  EXPECT_GT(max_speed, 4.0);              // it cruised
  EXPECT_LT(max_x, fence.max_x_m - 4.0);  // never within the shill's stand-off r0 of the wall
  EXPECT_LT(end_gap, 4.0);                // and reached the lane's end (the scout's waypoint radius)
  // Braking takes less tilt than the flight stack's 3 m/s^2 limit (17 deg) and the attitude does
  // not swing back and forth (with the velocity feedback: 26.7 deg, 3.95 rad/s, dozens of
  // reversals; with the limit on the command: 8.3 deg, 0.91 rad/s, none).
  EXPECT_LT(peak_tilt_braking, 17.0);
  EXPECT_LT(peak_pitch_rate, 2.0);
  EXPECT_LE(tilt_reversals, 2);
}

}  // namespace
}  // namespace swarmbox::flight::testing
