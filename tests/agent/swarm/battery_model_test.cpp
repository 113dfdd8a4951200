// BatteryModel (agent/swarm/battery_model.hpp): power model and the battery_low decision.
#include "swarmbox/swarm/battery_model.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace swarmbox::swarm {
namespace {

TEST(BatteryModel, KnownAirframesAndAClearErrorForOthers) {
  ASSERT_TRUE(BatterySpecFor("x500").ok());
  ASSERT_TRUE(BatterySpecFor("x8_heavy").ok());
  const Result<BatterySpec> r = BatterySpecFor("cessna");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code(), ErrorCode::kNotFound);
  EXPECT_NE(r.error().message().find("x500, x8_heavy"), std::string::npos);
}

TEST(BatteryModel, HoverPowerScalesWithMassToThePowerOneAndAHalf) {
  BatteryModel b(*BatterySpecFor("x8_heavy"));
  const double p0 = b.Power({0, 0, 0}, 0.0);
  EXPECT_DOUBLE_EQ(p0, b.spec().hover_power_w);
  EXPECT_NEAR(b.Power({0, 0, 0}, 80.0) / p0, std::pow(200.0 / 120.0, 1.5), 1e-12);
  EXPECT_GT(b.Power({5, 0, 0}, 0.0), p0);   // parasitic drag
  EXPECT_GT(b.Power({0, 0, 1}, 0.0), p0);   // climbing
}

TEST(BatteryModel, X500HoversAboutEighteenMinutes) {
  BatteryModel b(*BatterySpecFor("x500"));
  double t = 0;
  while (b.fraction() > 0.0 && t < 3600) {
    b.Step(1.0, {0, 0, 0}, 0.0);
    t += 1.0;
  }
  EXPECT_NEAR(t / 60.0, 17.7, 0.5);  // 59 Wh / 200 W [min], tolerance 0.5 min
}

TEST(BatteryModel, LowWhenTheEnergyHomeNoLongerFitsOrBelowTheFloor) {
  BatteryModel b(*BatterySpecFor("x500"));
  EXPECT_FALSE(b.IsLow(100.0, 30.0, 0.0));
  // Far from home: 6 km at 5 m/s is 20 min of cruise, more than a full pack.
  EXPECT_TRUE(b.IsLow(6000.0, 30.0, 0.0));
  // Drain to 25%: near home it is not low yet; 19% is low anywhere (low_fraction 0.20).
  BatteryModel c(*BatterySpecFor("x500"), 0.25);
  EXPECT_FALSE(c.IsLow(50.0, 30.0, 0.0));
  BatteryModel d(*BatterySpecFor("x500"), 0.19);
  EXPECT_TRUE(d.IsLow(0.0, 0.0, 0.0));
  // Energy home grows with distance and payload.
  EXPECT_GT(b.EnergyToHome(200, 30, 0), b.EnergyToHome(100, 30, 0));
  BatteryModel h(*BatterySpecFor("x8_heavy"));
  EXPECT_GT(h.EnergyToHome(100, 15, 80), h.EnergyToHome(100, 15, 0));
}

TEST(BatteryModel, GroundIdleDrawIsSmall) {
  BatteryModel b(*BatterySpecFor("x500"));
  b.Step(60.0, {0, 0, 0}, 0.0, /*airborne=*/false);
  EXPECT_GT(b.fraction(), 0.99);
  EXPECT_LT(b.fraction(), 1.0);
}

}  // namespace
}  // namespace swarmbox::swarm
