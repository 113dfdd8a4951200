// The SDK's own code (agent/brain/src/brain.cpp): command names, Context's argument readers,
// Output::Clear.
#include "swarmbox/brain/brain.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace swarmbox::brain {
namespace {

TEST(BrainSdk, CommandNamesAreTheOffboardTopicsNames) {
  EXPECT_STREQ(CommandName(Command::Kind::kArm), "arm");
  EXPECT_STREQ(CommandName(Command::Kind::kDisarm), "disarm");
  EXPECT_STREQ(CommandName(Command::Kind::kTakeoff), "takeoff");
  EXPECT_STREQ(CommandName(Command::Kind::kLand), "land");
  EXPECT_STREQ(CommandName(Command::Kind::kHold), "hold");
  EXPECT_STREQ(CommandName(Command::Kind::kPayloadAttach), "payload_attach");
  EXPECT_STREQ(CommandName(Command::Kind::kPayloadRelease), "payload_release");
}

TEST(BrainSdk, ArgDoubleReadsNumbersAndFallsBack) {
  Context ctx;
  ctx.args = {{"a", "12"}, {"b", "-0.25"}, {"c", "1e3"}};
  EXPECT_EQ(ctx.ArgDouble("a", 0.0), 12.0);
  EXPECT_EQ(ctx.ArgDouble("b", 0.0), -0.25);
  EXPECT_EQ(ctx.ArgDouble("c", 0.0), 1000.0);
  EXPECT_EQ(ctx.ArgDouble("missing", 3.5), 3.5);
}

TEST(BrainSdk, ArgDoubleRefusesWhatIsNotAWholeFiniteNumber) {
  Context ctx;
  ctx.args = {{"word", "fast"}, {"tail", "12m"}, {"empty", ""}, {"inf", "inf"}, {"nan", "nan"},
              {"huge", "1e999"}};
  for (const char* key : {"word", "tail", "empty", "inf", "nan", "huge"}) {
    try {
      ctx.ArgDouble(key, 0.0);
      ADD_FAILURE() << key << " was read as a number";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()), std::string("brain argument ") + key +
                                           ": expected a finite number, got \"" + ctx.args.at(key) + "\"");
    }
  }
}

TEST(BrainSdk, ArgStringGivesTheTextOrTheFallback) {
  Context ctx;
  ctx.args = {{"ring", R"({"n": 3})"}};
  EXPECT_EQ(ctx.ArgString("ring", ""), R"({"n": 3})");
  EXPECT_EQ(ctx.ArgString("missing", "dflt"), "dflt");
}

TEST(BrainSdk, OutputClearEmptiesEverything) {
  Output out;
  out.setpoint.push_back(Setpoint::Position({1, 2, 3}));
  out.commands.push_back(Command::Land());
  out.messages.push_back({"a", "", "t", {1}});
  out.proposals.push_back({1, 2});
  out.status = "x/y";
  out.events.push_back({"e", {{"k", "v"}}});
  out.Clear();
  EXPECT_TRUE(out.setpoint.empty());
  EXPECT_TRUE(out.commands.empty());
  EXPECT_TRUE(out.messages.empty());
  EXPECT_TRUE(out.proposals.empty());
  EXPECT_TRUE(out.status.empty());
  EXPECT_TRUE(out.events.empty());
}

TEST(BrainSdk, SetpointHelpersLeaveTheOtherFieldsUnset) {
  const Setpoint p = Setpoint::Position({1, 2, 3});
  EXPECT_EQ(p.position_m.z, 3.0);
  EXPECT_TRUE(std::isnan(p.velocity_m_s.x) && std::isnan(p.acceleration_m_s2.z));
  EXPECT_TRUE(std::isnan(p.yaw_rad) && std::isnan(p.yawspeed_rad_s));
}

}  // namespace
}  // namespace swarmbox::brain
