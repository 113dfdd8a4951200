#include "telemetry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <thread>

namespace swarmbox::agent {
namespace {

TEST(TelemetryClock, DueOnceAtEachMultipleOfThePeriod) {
  TelemetryClock clock(10.0);  // every 100 ms
  EXPECT_TRUE(clock.Due(0));
  EXPECT_FALSE(clock.Due(4'000'000));
  EXPECT_FALSE(clock.Due(96'000'000));
  EXPECT_TRUE(clock.Due(100'000'000));
  EXPECT_FALSE(clock.Due(104'000'000));
  // A gap (a stalled step) skips the multiples missed: one, not three.
  EXPECT_TRUE(clock.Due(452'000'000));
  EXPECT_FALSE(clock.Due(496'000'000));
  EXPECT_TRUE(clock.Due(500'000'000));
}

TEST(TelemetryClock, ZeroRateIsNeverDue) {
  TelemetryClock clock(0.0);
  EXPECT_FALSE(clock.enabled());
  EXPECT_FALSE(clock.Due(0));
  EXPECT_FALSE(clock.Due(1'000'000'000));
}

TEST(EventFromLogLine, SplitsTimeNodeNameAndFields) {
  const bus::Event e = EventFromLogLine("t=12.340 node=scout_1 event=leader_elected term=3 why=\"a b\"");
  EXPECT_EQ(e.sim_time_ns, 12'340'000'000);
  EXPECT_EQ(e.node, "scout_1");
  EXPECT_EQ(e.name, "leader_elected");
  ASSERT_EQ(e.fields.size(), 2u);
  EXPECT_EQ(e.fields[0].key, "term");
  EXPECT_EQ(e.fields[0].value, "3");
  EXPECT_EQ(e.fields[1].key, "why");
  EXPECT_EQ(e.fields[1].value, "a b");
}

TEST(EventFromLogLine, LineWithoutEventKeepsItsPairs) {
  const bus::Event e = EventFromLogLine("t=oops node=x k=v");
  EXPECT_EQ(e.name, "");
  EXPECT_EQ(e.sim_time_ns, 0);
  ASSERT_EQ(e.fields.size(), 2u);  // the unparsable t stays a field
  EXPECT_EQ(e.fields[0].key, "t");
  EXPECT_EQ(e.fields[1].key, "k");
}

TEST(EventQueue, HandsOverInPrintedOrderAndEmpties) {
  EventQueue q;
  std::thread writer([&] {
    for (int i = 0; i < 100; ++i) q.Push("t=1.000 node=a event=e" + std::to_string(i));
  });
  writer.join();
  std::vector<bus::Event> out;
  q.TakeInto(&out);
  ASSERT_EQ(out.size(), 100u);
  EXPECT_EQ(out.front().name, "e0");
  EXPECT_EQ(out.back().name, "e99");
  out.clear();
  q.TakeInto(&out);
  EXPECT_TRUE(out.empty());
}

TEST(LinkOf, ReadsPeerLossAndMeanRtt) {
  auto link = LinkOf(EventFromLogLine(
      "t=12.340 node=scout_1 event=link peer=scout_2 sent=10 received=9 loss=0.1000 late=0 dup=0 rtt_ms_mean=201.7 "
      "rtt_ms_sd=27.9"));
  ASSERT_TRUE(link.has_value());
  EXPECT_EQ(link->peer, "scout_2");
  EXPECT_DOUBLE_EQ(link->loss, 0.1);
  EXPECT_DOUBLE_EQ(link->rtt_ms, 201.7);
}

TEST(LinkOf, NoAnswersMeansNoRtt) {
  auto link = LinkOf(EventFromLogLine("t=1.000 node=a event=link peer=b sent=5 received=0 loss=1.0000 late=0 dup=0"));
  ASSERT_TRUE(link.has_value());
  EXPECT_DOUBLE_EQ(link->loss, 1.0);
  EXPECT_TRUE(std::isnan(link->rtt_ms));
}

TEST(LinkOf, OtherEventsAndMalformedLinksAreNotLinks) {
  EXPECT_FALSE(LinkOf(EventFromLogLine("t=1.000 node=a event=hover peer=b loss=0.5")).has_value());
  EXPECT_FALSE(LinkOf(EventFromLogLine("t=1.000 node=a event=link loss=0.5")).has_value());
  EXPECT_FALSE(LinkOf(EventFromLogLine("t=1.000 node=a event=link peer=b loss=lots")).has_value());
}

TEST(SectorsOf, RectanglesBecomeCounterClockwisePolygons) {
  std::vector<bus::TelemetrySector> out{{"stale", {1.0}}};
  SectorsOf({{"scout_1", -10, -5, 10, 5}, {"scout_2", 10, -5, 30, 5}}, &out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].drone, "scout_1");
  EXPECT_EQ(out[0].polygon_xy_m, (std::vector<double>{-10, -5, 10, -5, 10, 5, -10, 5}));
  EXPECT_EQ(out[1].drone, "scout_2");
}

}  // namespace
}  // namespace swarmbox::agent
