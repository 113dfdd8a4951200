#include "swarmbox/runner/end_matcher.hpp"

#include <gtest/gtest.h>

namespace swarmbox::runner {
namespace {

std::vector<dsl::EndCondition> Conditions() {
  return {
      {"event=mission_complete", dsl::Outcome::kSuccess, "", ""},
      {"event=collision", dsl::Outcome::kFailure, "collision", ""},
      {"event=crash", dsl::Outcome::kFailure, "crash", "physics"},
      {"event=battery_low .*level=0\\.0\\d", dsl::Outcome::kFailure, "battery", ""},
  };
}

struct Case {
  const char* component;
  const char* line;
  bool ends;
  dsl::Outcome outcome;
  const char* reason;
};

TEST(EndMatcher, MatchesLinesAsData) {
  auto m = EndMatcher::Compile(Conditions());
  ASSERT_TRUE(m);
  const Case cases[] = {
      {"scout_1", "t=5.000 node=scout_1 event=mission_complete", true, dsl::Outcome::kSuccess,
       "matched 'event=mission_complete'"},
      {"scout_1", "t=5.000 node=scout_1 event=collision other=scout_2", true, dsl::Outcome::kFailure,
       "collision"},
      // Token boundary: a longer event name does not match.
      {"scout_1", "t=5.000 node=scout_1 event=collision_avoided", false, dsl::Outcome::kSuccess, ""},
      {"scout_1", "t=5.000 node=scout_1 event=mission_completed", false, dsl::Outcome::kSuccess, ""},
      // Restricted to a component.
      {"scout_1", "t=5.000 node=scout_1 event=crash", false, dsl::Outcome::kSuccess, ""},
      {"physics", "t=5.000 node=physics event=crash drone=scout_1", true, dsl::Outcome::kFailure, "crash"},
      // A real regex.
      {"lifter", "t=9 node=lifter event=battery_low level=0.05", true, dsl::Outcome::kFailure, "battery"},
      {"lifter", "t=9 node=lifter event=battery_low level=0.25", false, dsl::Outcome::kSuccess, ""},
      {"lifter", "unrelated text", false, dsl::Outcome::kSuccess, ""},
  };
  for (const Case& c : cases) {
    auto v = m->Match(c.component, c.line);
    ASSERT_EQ(v.has_value(), c.ends) << c.line;
    if (!v) continue;
    EXPECT_EQ(v->outcome, c.outcome) << c.line;
    EXPECT_EQ(v->reason, c.reason) << c.line;
    EXPECT_EQ(v->source, c.component) << c.line;
  }
}

TEST(EndMatcher, FirstConditionInOrderWins) {
  auto m = EndMatcher::Compile(Conditions());
  ASSERT_TRUE(m);
  auto v = m->Match("x", "event=collision event=mission_complete");
  ASSERT_TRUE(v);
  EXPECT_EQ(v->outcome, dsl::Outcome::kSuccess);
}

TEST(EndMatcher, BadPatternIsReported) {
  auto m = EndMatcher::Compile({{"event=(", dsl::Outcome::kSuccess, "", ""}});
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().message().find("invalid log pattern 'event=('"), std::string::npos);
}

TEST(SimTimeOf, ReadsTheTField) {
  EXPECT_EQ(SimTimeOf("t=12.340 node=drone_2 event=leader_elected"), 12.34);
  EXPECT_EQ(SimTimeOf("node=x t=3 event=y"), 3.0);
  EXPECT_FALSE(SimTimeOf("event=y").has_value());
  EXPECT_FALSE(SimTimeOf("t=soon event=y").has_value());
  EXPECT_FALSE(SimTimeOf("start=5 event=y").has_value());
}

}  // namespace
}  // namespace swarmbox::runner
