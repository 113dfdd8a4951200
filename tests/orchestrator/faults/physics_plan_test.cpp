#include "swarmbox/faults/physics_plan.hpp"

#include <gtest/gtest.h>

namespace swarmbox::faults {
namespace {

Fault Make(FaultAction action, std::optional<std::int64_t> duration_ms) {
  Fault f;
  f.id = "f";
  f.duration_ms = duration_ms;
  f.action = std::move(action);
  return f;
}

TEST(PhysicsPlan, GpsDropoutCarriesItsDurationPerTargetAndNeedsNoUndo) {
  const PhysicsPlan plan = PlanPhysicsFault(Make(GpsDropout{}, 3000), {"scout_1", "scout_2"});
  EXPECT_EQ(plan.apply, (std::vector<WorldCommandCall>{{"scout_1", "gps_dropout", {3.0}},
                                                       {"scout_2", "gps_dropout", {3.0}}}));
  EXPECT_TRUE(plan.undo.empty());
}

TEST(PhysicsPlan, WithoutDurationADropoutLastsUntilTheEnd) {
  const PhysicsPlan plan = PlanPhysicsFault(Make(GpsDropout{}, std::nullopt), {"a"});
  EXPECT_EQ(plan.apply, (std::vector<WorldCommandCall>{{"a", "gps_dropout", {kUntilEndS}}}));
}

TEST(PhysicsPlan, GpsDegradeSendsDurationAndBothAccuraciesPerTargetAndNeedsNoUndo) {
  GpsDegrade degrade;
  degrade.h_acc_m = 5;
  degrade.v_acc_m = 8.5;
  const PhysicsPlan plan = PlanPhysicsFault(Make(degrade, 4000), {"scout_1", "scout_2"});
  // The physics server's order: duration_s, h_acc_m, v_acc_m; it restores the accuracy itself.
  EXPECT_EQ(plan.apply, (std::vector<WorldCommandCall>{{"scout_1", "gps_degrade", {4.0, 5.0, 8.5}},
                                                       {"scout_2", "gps_degrade", {4.0, 5.0, 8.5}}}));
  EXPECT_TRUE(plan.undo.empty());
  EXPECT_EQ(WorldCommandText(plan.apply[0]), "gps_degrade scout_1 4 5 8.5");
  EXPECT_TRUE(IsPhysicsFault(Make(degrade, 4000)));
  EXPECT_EQ(PlanPhysicsFault(Make(degrade, std::nullopt), {"a"}).apply,
            (std::vector<WorldCommandCall>{{"a", "gps_degrade", {kUntilEndS, 5.0, 8.5}}}));
}

TEST(PhysicsPlan, ImuBiasWithDurationIsTakenBackByTheNegatedJump) {
  ImuBias bias;
  bias.accel_m_s2 = {0.3, 0, 0};
  bias.gyro_rad_s = {0, 0, 0.02};
  const PhysicsPlan plan = PlanPhysicsFault(Make(bias, 30000), {"lifter"});
  EXPECT_EQ(plan.apply, (std::vector<WorldCommandCall>{{"lifter", "imu_bias_jump", {0.3, 0, 0, 0, 0, 0.02}}}));
  EXPECT_EQ(plan.undo, (std::vector<WorldCommandCall>{{"lifter", "imu_bias_jump", {-0.3, 0, 0, 0, 0, -0.02}}}));
  EXPECT_EQ(WorldCommandText(plan.undo[0]), "imu_bias_jump lifter -0.3 0 0 0 0 -0.02");
  EXPECT_TRUE(PlanPhysicsFault(Make(bias, std::nullopt), {"lifter"}).undo.empty());
}

TEST(PhysicsPlan, GustFromTheWestBlowsEastInEnuForTheWholeWorld) {
  WindGust gust;
  gust.speed_m_s = 12;
  gust.direction_deg = 270;
  gust.vertical_m_s = -1.5;
  const PhysicsPlan plan = PlanPhysicsFault(Make(gust, 5000), {"ignored"});
  EXPECT_EQ(plan.apply, (std::vector<WorldCommandCall>{{"", "wind_gust", {12.0, 0.0, -1.5, 5.0}}}));
  EXPECT_EQ(WorldCommandText(plan.apply[0]), "wind_gust - 12 0 -1.5 5");
  gust.direction_deg = 0;  // a northerly blows towards -y (south)
  EXPECT_EQ(GustVelocityEnu(gust), (std::array<double, 3>{0.0, -12.0, -1.5}));
}

TEST(PhysicsPlan, OtherKindsAreNotPhysicsFaults) {
  EXPECT_TRUE(IsPhysicsFault(Make(WindGust{}, 1000)));
  EXPECT_FALSE(IsPhysicsFault(Make(ProcessFault{}, 1000)));
  EXPECT_TRUE(PlanPhysicsFault(Make(ProcessFault{}, 1000), {"a"}).apply.empty());
}

}  // namespace
}  // namespace swarmbox::faults
