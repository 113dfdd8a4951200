// HoverThrustModule (the role of PX4's mc_hover_thrust_estimator module around its EKF): it learns
// only in the air and with thrust, feeds the thrust through the rotor lag, and de-weights fast
// vertical and horizontal flight past HTE_VZ_THR / HTE_VXY_THR.
#include "swarmbox/flight/hover_thrust_module.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace swarmbox::flight {
namespace {

constexpr double kDt = 0.004;
constexpr double kMaxThrustN = 60.0;

HoverThrustModule Made(double lag_s = 0.0) {
  HoverThrustModule m;
  HoverThrustModuleParams p;
  p.thrust_lag_s = lag_s;
  m.Configure(p, HoverThrustParams{}, kMaxThrustN);
  m.Reset(0.5);
  return m;
}

// One step of a vehicle whose true hover thrust is h_true, flown level at thrust_n.
bool Feed(HoverThrustModule& m, bool in_air, double thrust_n, double h_true, const Vec3& vel = Vec3::Zero()) {
  const double u = thrust_n / kMaxThrustN;
  const double acc = kGravity_m_s2 * u / h_true - kGravity_m_s2;
  return m.Update(in_air, thrust_n, 1.0, acc, vel, kDt);
}

TEST(HoverThrustModule, LearnsOnlyInTheAirAndWithThrust) {
  HoverThrustModule m = Made();
  for (int i = 0; i < 500; ++i) EXPECT_FALSE(Feed(m, /*in_air=*/false, 24.0, 0.4));
  EXPECT_DOUBLE_EQ(m.hover_thrust(), 0.5);
  EXPECT_FALSE(Feed(m, /*in_air=*/true, 0.0, 0.4));  // no thrust delivered: nothing to learn from
  for (int i = 0; i < 2500; ++i) EXPECT_TRUE(Feed(m, true, 24.0, 0.4));
  EXPECT_NEAR(m.hover_thrust(), 0.4, 0.01);
}

TEST(HoverThrustModule, FeedsTheThrustThroughTheRotorLag) {
  HoverThrustModule m = Made(/*lag_s=*/0.04);
  m.Update(false, 40.0, 1.0, 0.0, Vec3::Zero(), kDt);
  EXPECT_NEAR(m.delivered_thrust_n(), 40.0 * kDt / 0.04, 1e-12);  // one step of a 40 ms lag
  for (int i = 0; i < 200; ++i) m.Update(false, 40.0, 1.0, 0.0, Vec3::Zero(), kDt);
  EXPECT_NEAR(m.delivered_thrust_n(), 40.0, 1e-6);
  m.ClearThrust();  // motors off
  EXPECT_EQ(m.delivered_thrust_n(), 0.0);
  HoverThrustModule instant = Made(0.0);
  instant.Update(false, 40.0, 1.0, 0.0, Vec3::Zero(), kDt);
  EXPECT_EQ(instant.delivered_thrust_n(), 40.0);
}

TEST(HoverThrustModule, FastFlightLearnsMoreSlowly) {
  // The same wrong prior corrected in level hover and while climbing 6 m/s (4 m/s over HTE_VZ_THR):
  // the climb's measurements weigh less, so it has moved less after the same time.
  HoverThrustModule hover = Made();
  HoverThrustModule climb = Made();
  HoverThrustModule cruise = Made();
  const HoverThrustModuleParams p;
  for (int i = 0; i < 100; ++i) {
    Feed(hover, true, 24.0, 0.4);
    Feed(climb, true, 24.0, 0.4, Vec3(0.0, 0.0, p.vz_threshold_m_s + 4.0));
    Feed(cruise, true, 24.0, 0.4, Vec3(p.vxy_threshold_m_s + 4.0, 0.0, 0.0));
  }
  EXPECT_LT(std::abs(hover.hover_thrust() - 0.4), std::abs(climb.hover_thrust() - 0.4));
  EXPECT_LT(std::abs(hover.hover_thrust() - 0.4), std::abs(cruise.hover_thrust() - 0.4));
  // Below the thresholds no de-weighting: identical to the hover.
  HoverThrustModule slow = Made();
  HoverThrustModule still = Made();
  for (int i = 0; i < 100; ++i) {
    Feed(slow, true, 24.0, 0.4, Vec3(p.vxy_threshold_m_s - 1.0, 0.0, p.vz_threshold_m_s - 1.0));
    Feed(still, true, 24.0, 0.4);
  }
  EXPECT_DOUBLE_EQ(slow.hover_thrust(), still.hover_thrust());
}

TEST(HoverThrustModule, ResetStartsOverWithNoThrustDelivered) {
  HoverThrustModule m = Made();
  for (int i = 0; i < 1000; ++i) Feed(m, true, 24.0, 0.4);
  m.Reset(0.6);
  EXPECT_DOUBLE_EQ(m.hover_thrust(), 0.6);
  EXPECT_EQ(m.delivered_thrust_n(), 0.0);
}

}  // namespace
}  // namespace swarmbox::flight
