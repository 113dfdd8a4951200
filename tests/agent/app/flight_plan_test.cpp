// FlightPlan: the agent's built-in plan as a SetpointSource, driven on simulated time.
#include "flight_plan.hpp"

#include <gtest/gtest.h>

namespace swarmbox::agent {
namespace {

using flight::FlightMode;
using flight::Setpoint;

TEST(FlightPlan, ParsesEveryStepKind) {
  auto plan = FlightPlan::Parse("takeoff:5,hover:10,goto:10:-2:5:90,velocity:1:0:0:3,land");
  ASSERT_TRUE(plan.ok()) << plan.error().ToString();
  ASSERT_EQ(plan->steps().size(), 5u);
  EXPECT_EQ(plan->steps()[0].kind, FlightPlan::Step::Kind::kTakeoff);
  EXPECT_DOUBLE_EQ(plan->steps()[0].value.z(), 5.0);
  EXPECT_DOUBLE_EQ(plan->steps()[2].value.y(), -2.0);
  EXPECT_NEAR(plan->steps()[2].yaw_rad, flight::kPi / 2.0, 1e-12);
  EXPECT_DOUBLE_EQ(plan->steps()[3].duration_s, 3.0);
}

TEST(FlightPlan, RejectsBadStepsWithTheStepAndTheAcceptedForms) {
  auto plan = FlightPlan::Parse("takeoff:5,hover:x");
  ASSERT_FALSE(plan.ok());
  EXPECT_NE(plan.error().message().find("hover:x"), std::string::npos) << plan.error().message();
  EXPECT_NE(plan.error().message().find("goto:X:Y:Z"), std::string::npos) << plan.error().message();
  EXPECT_FALSE(FlightPlan::Parse("jump:3").ok());
  EXPECT_FALSE(FlightPlan::Parse("takeoff:-1").ok());
  EXPECT_FALSE(FlightPlan::Parse("").ok());
}

TEST(FlightPlan, WaitsPreflightThenSequencesOnControllerEvents) {
  auto plan = FlightPlan::Parse("takeoff:5,hover:2,land");
  ASSERT_TRUE(plan.ok());
  plan->SetPreflight(1.0);
  FlightStatus st;
  st.mode = FlightMode::kInit;
  EXPECT_FALSE(plan->Tick(st).has_value());  // not ready yet
  st.mode = FlightMode::kIdle;
  st.t_s = 1.0;
  EXPECT_FALSE(plan->Tick(st).has_value());  // pre-flight wait starts
  st.t_s = 2.0;
  auto sp = plan->Tick(st);
  ASSERT_TRUE(sp.has_value());
  EXPECT_EQ(sp->kind, Setpoint::Kind::kTakeoff);
  st.mode = FlightMode::kTakeoff;
  st.t_s = 3.0;
  EXPECT_FALSE(plan->Tick(st).has_value());  // climbing
  st.mode = FlightMode::kHold;
  st.hover = true;
  st.t_s = 6.0;
  EXPECT_FALSE(plan->Tick(st).has_value());  // take-off done
  st.hover = false;
  sp = plan->Tick(st);
  ASSERT_TRUE(sp.has_value());
  EXPECT_EQ(sp->kind, Setpoint::Kind::kHold);
  st.t_s = 7.0;
  EXPECT_FALSE(plan->Tick(st).has_value());
  st.t_s = 8.0;
  EXPECT_FALSE(plan->Tick(st).has_value());  // 2 s of hover elapsed
  sp = plan->Tick(st);
  ASSERT_TRUE(sp.has_value());
  EXPECT_EQ(sp->kind, Setpoint::Kind::kLand);
  EXPECT_FALSE(plan->finished());
  st.landed = true;
  st.mode = FlightMode::kLanded;
  EXPECT_FALSE(plan->Tick(st).has_value());
  EXPECT_TRUE(plan->finished());
  EXPECT_EQ(plan->current(), "done");
}

}  // namespace
}  // namespace swarmbox::agent
