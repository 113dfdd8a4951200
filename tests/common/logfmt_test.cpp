#include "swarmbox/common/logfmt.hpp"

#include <gtest/gtest.h>

namespace swarmbox {
namespace {

TEST(LogEvent, FormatsTheContractLine) {
  LogEvent e(12.34, "drone_2", "leader_elected");
  e.Add("term", 3).Add("leader", "drone_2");
  EXPECT_EQ(e.str(), "t=12.340 node=drone_2 event=leader_elected term=3 leader=drone_2");
}

TEST(LogEvent, QuotesValuesThatNeedIt) {
  LogEvent e(0.0, "physics", "error");
  e.Add("reason", "no such file").Add("empty", "").Add("q", "a\"b").Add("x", 1.5, 1).Add("ok", true);
  EXPECT_EQ(e.str(), R"(t=0.000 node=physics event=error reason="no such file" empty="" q="a\"b" x=1.5 ok=true)");
}

TEST(ParseLogfmt, ReadsBackWhatLogEventWrites) {
  LogEvent e(1.0, "drone_1", "victim_confirmed");
  e.Add("id", "v1").Add("note", "two sightings = confirmed\tok");
  auto fields = ParseLogfmt(e.str());
  ASSERT_EQ(fields.size(), 5u);
  EXPECT_EQ(*FindField(fields, "event"), "victim_confirmed");
  EXPECT_EQ(*FindField(fields, "note"), "two sightings = confirmed\tok");
  EXPECT_EQ(*FindField(fields, "t"), "1.000");
  EXPECT_FALSE(FindField(fields, "missing").has_value());
}

TEST(ParseLogfmt, NonLogfmtLineGivesNothing) {
  EXPECT_TRUE(ParseLogfmt("Segmentation fault (core dumped)").empty());
  EXPECT_TRUE(ParseLogfmt("").empty());
}

TEST(ParseLogfmt, ToleratesTrailingCarriageReturnAndBareWords) {
  auto fields = ParseLogfmt("WARN t=1 event=battery_low\r");
  ASSERT_EQ(fields.size(), 3u);
  EXPECT_EQ(fields[0].first, "WARN");
  EXPECT_EQ(*FindField(fields, "event"), "battery_low");
}

}  // namespace
}  // namespace swarmbox
