// Channel: determinism (same seed, same deliveries; call order does not matter), delivery order,
// partitions and drones out of the world.
#include "swarmbox/channel/channel.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <tuple>

#include "channel_fixture.hpp"

namespace swarmbox::channel {
namespace {

using testing::Broadcast;
using testing::CleanProfile;
using testing::LineUp;
using testing::SameDeliveries;

RadioProfile WifiProfile() {
  auto p = LoadRadioProfile(testing::TrialsDir() + "/radios/wifi_5ghz_mesh.yaml");
  EXPECT_TRUE(p.ok()) << (p.ok() ? "" : p.error().ToString());
  return *p;
}

// 10 drones on a 3 x 4 grid 150 m apart (some links near 50 % PER), moving slowly, all
// broadcasting at 10 Hz for 10 s under a jittery lossy impairment. `reverse` hands each step's
// frames to the channel in reverse drone order.
std::vector<Delivery> RunSwarm(std::uint64_t seed, bool reverse, ChannelStats* stats = nullptr) {
  const std::size_t n = 10;
  Channel ch(WifiProfile(), n, seed, {Box{{200, -20, 0}, {220, 400, 40}}});
  Impairment imp;
  imp.delay_ms = 20;
  imp.jitter_ms = 5;
  imp.loss = 0.05;
  imp.duplicate = 0.02;
  ch.SetImpairment(std::nullopt, imp);
  std::vector<Vec3d> pos(n);
  std::vector<Delivery> got;
  for (std::int64_t k = 0; k <= 2500; ++k) {
    const std::int64_t t = k * 4'000'000;
    for (std::size_t i = 0; i < n; ++i) {
      pos[i] = {static_cast<double>(i % 4) * 150.0 + 0.5 * static_cast<double>(k) * 0.004,
                static_cast<double>(i / 4) * 150.0, 30.0};
    }
    ch.SetPositions(pos);
    ch.TakeDeliveries(t, &got);
    if (k % 25 == 0) {
      for (std::size_t j = 0; j < n; ++j) {
        const std::size_t i = reverse ? n - 1 - j : j;
        ch.Send(t, Broadcast(i, static_cast<std::uint64_t>(k / 25), t, 120));
      }
    }
  }
  if (stats != nullptr) *stats = ch.stats();
  return got;
}

TEST(ChannelDeterminism, SameSeedGivesTheSameDeliveries) {
  const auto a = RunSwarm(42, false);
  const auto b = RunSwarm(42, false);
  ASSERT_GT(a.size(), 1000u);
  EXPECT_TRUE(SameDeliveries(a, b));
}

TEST(ChannelDeterminism, DifferentSeedGivesDifferentDeliveries) {
  ChannelStats sa, sb;
  const auto a = RunSwarm(42, false, &sa);
  const auto b = RunSwarm(43, false, &sb);
  EXPECT_FALSE(SameDeliveries(a, b));
  EXPECT_EQ(sa.sent, sb.sent);
}

TEST(ChannelDeterminism, SendOrderAcrossSendersDoesNotMatter) {
  ChannelStats sa, sb;
  const auto a = RunSwarm(7, false, &sa);
  const auto b = RunSwarm(7, true, &sb);
  EXPECT_TRUE(SameDeliveries(a, b));
  EXPECT_EQ(sa.lost_per, sb.lost_per);
  EXPECT_EQ(sa.lost_impairment, sb.lost_impairment);
  // The swarm exercises every cause that is in play.
  EXPECT_GT(sa.lost_per, 0u);
  EXPECT_GT(sa.lost_impairment, 0u);
  EXPECT_GT(sa.duplicated, 0u);
}

TEST(ChannelDeterminism, DeliveriesAreSortedByTimeSenderSeqReceiver) {
  const auto got = RunSwarm(42, false);
  for (std::size_t i = 1; i < got.size(); ++i) {
    const auto& a = got[i - 1];
    const auto& b = got[i];
    EXPECT_LE(std::tie(a.at_ns, a.packet.from, a.packet.seq, a.to), std::tie(b.at_ns, b.packet.from, b.packet.seq, b.to));
  }
}

TEST(ChannelDeterminism, TakingStepByStepEqualsOneTake) {
  auto run = [](bool stepwise) {
    Channel ch(CleanProfile(), 3, 1, {});
    const auto pos = LineUp(3, 50);
    ch.SetPositions(pos);
    Impairment imp;
    imp.delay_ms = 30;
    imp.jitter_ms = 20;
    ch.SetImpairment(std::nullopt, imp);
    for (std::uint64_t s = 0; s < 50; ++s) {
      for (std::size_t i = 0; i < 3; ++i) ch.Send(0, Broadcast(i, s, 0, 500));
    }
    std::vector<Delivery> got;
    if (stepwise) {
      testing::StepTo(ch, 0, 2'000'000'000, &got);
    } else {
      ch.TakeDeliveries(2'000'000'000, &got);
    }
    return got;
  };
  const auto a = run(true);
  const auto b = run(false);
  ASSERT_EQ(a.size(), 300u);  // 3 senders x 50 frames x 2 receivers
  EXPECT_TRUE(SameDeliveries(a, b));
}

TEST(ChannelPartition, BlockedIsOneWayAndCanBeLifted) {
  Channel ch(CleanProfile(), 2, 1, {});
  ch.SetPositions(LineUp(2, 10));
  ch.SetBlocked(0, 1, true);
  std::vector<Delivery> got;
  ch.Send(0, Broadcast(0, 1, 0));
  ch.Send(0, Broadcast(1, 1, 0));
  ch.TakeDeliveries(100'000'000, &got);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].packet.from, 1u);
  EXPECT_EQ(got[0].to, 0u);
  EXPECT_EQ(ch.stats().lost_partition, 1u);

  ch.SetBlocked(0, 1, false);
  got.clear();
  ch.Send(100'000'000, Broadcast(0, 2, 100'000'000));
  ch.TakeDeliveries(200'000'000, &got);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].to, 1u);
}

TEST(ChannelOut, AnOutDroneNeitherSendsNorHears) {
  Channel ch(CleanProfile(), 3, 1, {});
  ch.SetPositions(LineUp(3, 10));
  ch.SetOut(2, true);
  std::vector<Delivery> got;
  ch.Send(0, Broadcast(0, 1, 0));
  ch.Send(0, Broadcast(2, 1, 0));
  ch.TakeDeliveries(100'000'000, &got);
  ASSERT_EQ(got.size(), 1u);  // 0 -> 1 only
  EXPECT_EQ(got[0].packet.from, 0u);
  EXPECT_EQ(got[0].to, 1u);
  EXPECT_EQ(ch.stats().lost_out, 2u);  // 2's own frame, and 0's frame at 2

  ch.SetOut(2, false);
  got.clear();
  ch.Send(100'000'000, Broadcast(2, 2, 100'000'000));
  ch.TakeDeliveries(200'000'000, &got);
  EXPECT_EQ(got.size(), 2u);
}

TEST(ChannelOut, FramesQueuedByADroneThatGoesOutAreDropped) {
  Channel ch(CleanProfile(), 2, 1, {});
  ch.SetPositions(LineUp(2, 10));
  Impairment imp;
  imp.delay_ms = 50;
  ch.SetImpairment(0, imp);
  ch.Send(0, Broadcast(0, 1, 0));
  std::vector<Delivery> got;
  ch.TakeDeliveries(20'000'000, &got);
  ch.SetOut(0, true);  // killed while its frame is in the impairment's delay line
  ch.TakeDeliveries(200'000'000, &got);
  EXPECT_TRUE(got.empty());
  EXPECT_EQ(ch.stats().lost_out, 1u);
}

}  // namespace
}  // namespace swarmbox::channel
