// --brain and its flags: the combinations refused with their reason, the brain period in
// lockstep steps (only rates that divide the 250 Hz lockstep).
#include "brain_options.hpp"

#include <gtest/gtest.h>

namespace swarmbox::agent {
namespace {

std::string Why(const BrainOptions& o, bool mission = false, bool plan = false) {
  const Status s = ValidateBrainOptions(o, mission, plan);
  return s ? std::string() : s.error().ToString();
}

TEST(BrainOptions, ParsesTheThreeKinds) {
  EXPECT_EQ(*ParseBrainKind("builtin"), BrainKind::kBuiltin);
  EXPECT_EQ(*ParseBrainKind("library"), BrainKind::kLibrary);
  EXPECT_EQ(*ParseBrainKind("external"), BrainKind::kExternal);
  auto bad = ParseBrainKind("python");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().ToString().find("expected builtin, library or external"), std::string::npos);
  EXPECT_EQ(BrainKindName(BrainKind::kExternal), "external");
}

TEST(BrainOptions, RefusesBadCombinationsWithTheReason) {
  BrainOptions lib;
  lib.kind = BrainKind::kLibrary;
  EXPECT_NE(Why(lib).find("needs --brain-library PATH"), std::string::npos);
  lib.library_path = "x.so";
  EXPECT_NE(Why(lib).find("needs --brain-name NAME"), std::string::npos);
  lib.name = "rendezvous";
  EXPECT_EQ(Why(lib), "");
  EXPECT_NE(Why(lib, true).find("--mission is for --brain builtin"), std::string::npos);
  EXPECT_NE(Why(lib, false, true).find("--plan is for --brain builtin"), std::string::npos);
  BrainOptions builtin;
  builtin.name = "x";
  EXPECT_NE(Why(builtin).find("--brain-name is for --brain library"), std::string::npos);
  builtin.name.clear();
  builtin.library_path = "x.so";
  EXPECT_NE(Why(builtin).find("--brain-library is for --brain library"), std::string::npos);
  EXPECT_EQ(Why(BrainOptions{}, true, true), "");
  BrainOptions ext;
  ext.kind = BrainKind::kExternal;
  ext.offboard_timeout_ms = 0;
  EXPECT_NE(Why(ext).find("--offboard-timeout-ms must be > 0"), std::string::npos);
  ext.offboard_timeout_ms = 1000;
  ext.offboard_hold_ms = -1;
  EXPECT_NE(Why(ext).find("--offboard-hold-ms must be >= 0"), std::string::npos);
  ext.offboard_hold_ms = 0;
  ext.wait_ms = 0;
  EXPECT_NE(Why(ext).find("--brain-wait-ms"), std::string::npos);
  BrainOptions none;
  EXPECT_EQ(none.neighbours, 32);
  none.neighbours = 0;
  EXPECT_NE(Why(none).find("--brain-neighbours must be > 0"), std::string::npos);
}

TEST(BrainOptions, ThePeriodIsAWholeNumberOfLockstepSteps) {
  BrainOptions o;
  EXPECT_EQ(*BrainPeriodSteps(o, 0.004), 1);  // every step
  o.kind = BrainKind::kExternal;
  EXPECT_EQ(*BrainPeriodSteps(o, 0.004), 5);  // 50 Hz
  o.rate_hz = 10;
  EXPECT_EQ(*BrainPeriodSteps(o, 0.004), 25);
  o.rate_hz = 250;
  EXPECT_EQ(*BrainPeriodSteps(o, 0.004), 1);
  o.rate_hz = 60;
  auto bad = BrainPeriodSteps(o, 0.004);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().ToString().find("--brain-rate-hz 60"), std::string::npos) << bad.error().ToString();
  EXPECT_NE(bad.error().ToString().find("(250 per second): e.g. 250, 125, 50, 25, 10"), std::string::npos) << bad.error().ToString();
  o.rate_hz = 62.5;  // every 4 steps
  EXPECT_EQ(*BrainPeriodSteps(o, 0.004), 4);
  o.rate_hz = 500;  // faster than the lockstep
  EXPECT_FALSE(BrainPeriodSteps(o, 0.004));
  o.rate_hz = 1;  // a period of 1000 ms: as long as the offboard timeout
  auto slow = BrainPeriodSteps(o, 0.004);
  ASSERT_FALSE(slow);
  EXPECT_NE(slow.error().ToString().find("the brain period (1000 ms) must be shorter than --offboard-timeout-ms (1000)"),
            std::string::npos)
      << slow.error().ToString();
  o.offboard_timeout_ms = 1500;
  EXPECT_EQ(*BrainPeriodSteps(o, 0.004), 250);
}

}  // namespace
}  // namespace swarmbox::agent
