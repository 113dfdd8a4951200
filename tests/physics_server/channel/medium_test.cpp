// The shared medium: airtime and propagation, many talkers delaying each other, round-robin
// service, full queues dropping, the capacity bound.
#include <gtest/gtest.h>

#include <map>

#include "channel_fixture.hpp"
#include "swarmbox/channel/channel.hpp"

namespace swarmbox::channel {
namespace {

using testing::Broadcast;
using testing::CleanProfile;
using testing::LineUp;

TEST(ChannelMedium, OneFrameArrivesAfterItsAirtimeAndPropagation) {
  Channel ch(CleanProfile(), 2, 1, {});
  ch.SetPositions(LineUp(2, 300));
  Packet p;
  p.from = 0;
  p.to = 1;
  p.size_bytes = 200;
  p.sent_ns = 1'000'000;
  ch.Send(1'000'000, p);
  std::vector<Delivery> got;
  ch.TakeDeliveries(10'000'000, &got);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(ch.AirtimeNs(200), 1'700'000);  // 200 B * 8 / 1 Mb/s + 100 us
  EXPECT_EQ(got[0].at_ns, 1'000'000 + 1'700'000 + 1001);  // + 300 m / c
  EXPECT_EQ(ch.stats().medium_busy_ns, 1'700'000);
}

TEST(ChannelMedium, ManyTalkersDelayEachOther) {
  const std::size_t n = 20;
  Channel ch(CleanProfile(), n, 1, {});
  ch.SetPositions(LineUp(n, 5));
  for (std::size_t i = 0; i < n; ++i) ch.Send(0, Broadcast(i, 1, 0, 200));
  std::vector<Delivery> got;
  ch.TakeDeliveries(1'000'000'000, &got);
  ASSERT_EQ(got.size(), n * (n - 1));
  // Round-robin from sender 0: sender i's frame is the (i+1)-th on the air.
  for (const Delivery& d : got) {
    const auto slot_end = static_cast<std::int64_t>(d.packet.from + 1) * 1'700'000;
    EXPECT_GE(d.at_ns, slot_end);
    EXPECT_LT(d.at_ns, slot_end + 1000);  // propagation over < 100 m
  }
  EXPECT_EQ(ch.stats().medium_busy_ns, static_cast<std::int64_t>(n) * 1'700'000);
}

TEST(ChannelMedium, QueuesAreServedRoundRobinBySender) {
  Channel ch(CleanProfile(), 3, 1, {});
  ch.SetPositions(LineUp(3, 5));
  for (std::uint64_t s = 0; s < 20; ++s) ch.Send(0, Broadcast(0, s, 0, 200));
  ch.Send(0, Broadcast(1, 0, 0, 200));
  std::vector<Delivery> got;
  ch.TakeDeliveries(1'000'000'000, &got);
  std::vector<std::pair<std::size_t, std::uint64_t>> heard_by_2;
  for (const Delivery& d : got) {
    if (d.to == 2) heard_by_2.emplace_back(d.packet.from, d.packet.seq);
  }
  ASSERT_EQ(heard_by_2.size(), 21u);
  EXPECT_EQ(heard_by_2[0], std::make_pair(std::size_t{0}, std::uint64_t{0}));
  EXPECT_EQ(heard_by_2[1], std::make_pair(std::size_t{1}, std::uint64_t{0}));  // not behind all of 0's
  EXPECT_EQ(heard_by_2[2], std::make_pair(std::size_t{0}, std::uint64_t{1}));
}

TEST(ChannelMedium, AFullQueueDrops) {
  Channel ch(CleanProfile(), 2, 1, {});  // queue_frames 50
  ch.SetPositions(LineUp(2, 5));
  for (std::uint64_t s = 0; s < 60; ++s) ch.Send(0, Broadcast(0, s, 0, 200));
  std::vector<Delivery> got;
  ch.TakeDeliveries(1'000'000'000, &got);
  EXPECT_EQ(ch.stats().lost_queue, 10u);
  ASSERT_EQ(got.size(), 50u);
  EXPECT_EQ(got.back().packet.seq, 49u);  // the FIFO kept the oldest
}

// Offered load 16x what the medium carries: the medium stays busy, every sender gets its turn,
// and the queues overflow.
TEST(ChannelMedium, CongestionSharesTheMediumFairlyAndDrops) {
  const std::size_t n = 20;
  Channel ch(CleanProfile(), n, 1, {});
  ch.SetPositions(LineUp(n, 2));
  std::vector<Delivery> got;
  const std::int64_t airtime = ch.AirtimeNs(1000);  // 8.1 ms
  for (std::int64_t t = 0; t < 2'000'000'000; t += 10'000'000) {
    ch.TakeDeliveries(t, &got);
    for (std::size_t i = 0; i < n; ++i) ch.Send(t, Broadcast(i, static_cast<std::uint64_t>(t / 10'000'000), t, 1000));
  }
  ch.TakeDeliveries(2'000'000'000, &got);
  const ChannelStats& s = ch.stats();
  EXPECT_NEAR(static_cast<double>(s.transmitted), 2e9 / static_cast<double>(airtime), 2.0);
  EXPECT_GT(s.lost_queue, 2500u);  // 4000 offered - 247 carried - 1000 queued
  std::map<std::size_t, int> per_sender;  // frames on the air per sender, seen by its neighbour
  for (const Delivery& d : got) {
    if (d.to == (d.packet.from + 1) % n) ++per_sender[d.packet.from];
  }
  ASSERT_EQ(per_sender.size(), n);
  for (const auto& [sender, count] : per_sender) {
    EXPECT_NEAR(count, static_cast<double>(s.transmitted) / static_cast<double>(n), 1.0) << "sender " << sender;
  }
  // Queueing delay: the last frames delivered waited for a full round of queues.
  EXPECT_GT(got.back().at_ns - got.back().packet.sent_ns, 10 * airtime);
}

TEST(ChannelMedium, CapacityBelowTheDataRateHoldsTheMediumLonger) {
  RadioProfile p = CleanProfile();
  p.capacity_bps = 0.5e6;  // 1000 B hold the medium 16 ms, airtime 8.1 ms
  Channel ch(p, 3, 1, {});
  ch.SetPositions(LineUp(3, 5));
  ch.Send(0, Broadcast(0, 0, 0, 1000));
  ch.Send(0, Broadcast(1, 0, 0, 1000));
  std::vector<Delivery> got;
  ch.TakeDeliveries(1'000'000'000, &got);
  ASSERT_EQ(got.size(), 4u);
  EXPECT_LT(got[0].at_ns, 8'200'000);
  EXPECT_GE(got[3].at_ns, 16'000'000 + 8'100'000);
  EXPECT_EQ(ch.stats().medium_busy_ns, 32'000'000);
}

}  // namespace
}  // namespace swarmbox::channel
