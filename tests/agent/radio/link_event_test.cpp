// The event=link line: exact format, and parsing it back (also with a logger's prefix).
#include "swarmbox/radio/link_event.hpp"

#include <gtest/gtest.h>

namespace swarmbox::radio {
namespace {

LinkWindow Window() {
  LinkWindow w;
  w.peer = "scout_2";
  w.sent = 10;
  w.received = 9;
  w.late = 1;
  w.duplicates = 0;
  w.rtt = SummariseRtt({190.0, 200.0, 210.0, 195.0, 205.0, 199.0, 201.0, 250.0, 180.0});
  return w;
}

TEST(FormatLinkEvent, WritesTheContractFields) {
  EXPECT_EQ(FormatLinkEvent(12.34, "scout_1", Window()).str(),
            "t=12.340 node=scout_1 event=link peer=scout_2 sent=10 received=9 loss=0.1000 late=1 "
            "dup=0 rtt_ms_mean=203.33 rtt_ms_sd=19.53 rtt_ms_p50=200.00 rtt_ms_p99=250.00 "
            "rtt_ms_max=250.00");
}

TEST(FormatLinkEvent, OmitsRttWhenNothingCameBack) {
  LinkWindow w;
  w.peer = "lifter";
  w.sent = 5;
  EXPECT_EQ(FormatLinkEvent(3.0, "scout_1", w).str(),
            "t=3.000 node=scout_1 event=link peer=lifter sent=5 received=0 loss=1.0000 late=0 dup=0");
}

TEST(ParseLinkLine, ReadsBackWhatFormatWrote) {
  const std::string line = "scout_1 | " + FormatLinkEvent(12.34, "scout_1", Window()).str();
  auto l = ParseLinkLine(line);
  ASSERT_TRUE(l);
  EXPECT_DOUBLE_EQ(l->t_s, 12.34);
  EXPECT_EQ(l->node, "scout_1");
  EXPECT_EQ(l->peer, "scout_2");
  EXPECT_EQ(l->sent, 10u);
  EXPECT_EQ(l->received, 9u);
  EXPECT_DOUBLE_EQ(l->loss, 0.1);
  EXPECT_EQ(l->late, 1u);
  EXPECT_TRUE(l->has_rtt);
  EXPECT_DOUBLE_EQ(l->rtt_ms_mean, 203.33);
  EXPECT_DOUBLE_EQ(l->rtt_ms_sd, 19.53);
  EXPECT_DOUBLE_EQ(l->rtt_ms_p50, 200.0);
  EXPECT_DOUBLE_EQ(l->rtt_ms_p99, 250.0);
}

TEST(ParseLinkLine, RefusesOtherEventsAndIncompleteLines) {
  EXPECT_FALSE(ParseLinkLine("t=1.000 node=a event=hover alt=5"));
  EXPECT_FALSE(ParseLinkLine("t=1.000 node=a event=link peer=b sent=1"));
  EXPECT_FALSE(ParseLinkLine("t=1.000 node=a event=link peer=b sent=x received=1 loss=0"));
  EXPECT_FALSE(ParseLinkLine("no logfmt here"));
  auto l = ParseLinkLine("t=1.000 node=a event=link peer=b sent=3 received=0 loss=1.0000");
  ASSERT_TRUE(l);
  EXPECT_FALSE(l->has_rtt);
}

}  // namespace
}  // namespace swarmbox::radio
