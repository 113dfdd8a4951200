// The sender's egress impairment (netem semantics): delay and jitter distributions, loss,
// duplicates, the rate serialiser, and the distributions the channel refuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "channel_fixture.hpp"
#include "swarmbox/channel/channel.hpp"

namespace swarmbox::channel {
namespace {

using testing::CleanProfile;
using testing::LineUp;
using testing::SendStream;

struct DelayStats {
  double median_ms = 0, mean_ms = 0, std_ms = 0, min_ms = 0, max_ms = 0;
};

// One-way delays minus the frame's airtime and propagation (what the impairment added) [ms].
DelayStats ImpairmentDelays(const Channel& ch, const std::vector<Delivery>& got, double distance_m) {
  std::vector<double> d;
  const double fixed_ns = static_cast<double>(ch.AirtimeNs(100)) + distance_m / 299792458.0 * 1e9;
  for (const Delivery& x : got) d.push_back((static_cast<double>(x.at_ns - x.packet.sent_ns) - fixed_ns) * 1e-6);
  std::sort(d.begin(), d.end());
  DelayStats s;
  s.median_ms = d[d.size() / 2];
  s.mean_ms = std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(d.size());
  double sq = 0;
  for (double v : d) sq += (v - s.mean_ms) * (v - s.mean_ms);
  s.std_ms = std::sqrt(sq / static_cast<double>(d.size()));
  s.min_ms = d.front();
  s.max_ms = d.back();
  return s;
}

// The figure: delay 150 jitter 10 loss 0.10 -> one-way median ~150 ms, loss ~10 %.
TEST(ChannelImpairment, DelayJitterLossMatchTheSpecOverTenThousandFrames) {
  Channel ch(CleanProfile(), 2, 42, {});
  ch.SetPositions(LineUp(2, 10));
  Impairment imp;
  imp.delay_ms = 150;
  imp.jitter_ms = 10;
  imp.loss = 0.10;
  ch.SetImpairment(std::nullopt, imp);
  const auto got = SendStream(ch, 10000, 100'000'000);
  const double loss = 1.0 - static_cast<double>(got.size()) / 10000.0;
  EXPECT_NEAR(loss, 0.10, 0.01);  // binomial sd 0.003
  EXPECT_EQ(ch.stats().lost_impairment, 10000u - got.size());
  const DelayStats s = ImpairmentDelays(ch, got, 10);
  EXPECT_NEAR(s.median_ms, 150.0, 0.5);
  EXPECT_NEAR(s.std_ms, 10.0, 0.5);  // normal jitter: sd = jitter_ms
  EXPECT_LT(s.min_ms, 125.0);        // tails of a normal beyond 2.5 sd in 9,000 draws
  EXPECT_GT(s.max_ms, 175.0);
}

TEST(ChannelImpairment, UniformJitterStaysWithinDelayPlusMinusJitter) {
  Channel ch(CleanProfile(), 2, 42, {});
  ch.SetPositions(LineUp(2, 10));
  Impairment imp;
  imp.delay_ms = 100;
  imp.jitter_ms = 20;
  imp.distribution = "uniform";
  ch.SetImpairment(0, imp);
  const auto got = SendStream(ch, 5000, 100'000'000);
  ASSERT_EQ(got.size(), 5000u);
  const DelayStats s = ImpairmentDelays(ch, got, 10);
  EXPECT_GE(s.min_ms, 80.0 - 1e-6);
  EXPECT_LE(s.max_ms, 120.0 + 1e-6);
  EXPECT_NEAR(s.mean_ms, 100.0, 0.5);
  EXPECT_NEAR(s.std_ms, 20.0 / std::sqrt(3.0), 0.5);
}

TEST(ChannelImpairment, DuplicateAddsCopies) {
  Channel ch(CleanProfile(), 2, 42, {});
  ch.SetPositions(LineUp(2, 10));
  Impairment imp;
  imp.duplicate = 0.2;
  imp.delay_ms = 1;
  ch.SetImpairment(std::nullopt, imp);
  const auto got = SendStream(ch, 10000, 10'000'000);
  EXPECT_NEAR(static_cast<double>(got.size()) / 10000.0, 1.2, 0.015);
  EXPECT_EQ(ch.stats().duplicated, got.size() - 10000u);
}

TEST(ChannelImpairment, RateSerialisesTheSendersFrames) {
  Channel ch(CleanProfile(), 2, 42, {});
  ch.SetPositions(LineUp(2, 10));
  Impairment imp;
  imp.rate_kbit = 80;  // a 1000-byte frame takes 100 ms
  ch.SetImpairment(0, imp);
  Packet p;
  p.from = 0;
  p.to = 1;
  p.size_bytes = 1000;
  for (std::uint64_t s = 0; s < 5; ++s) {
    p.seq = s;
    ch.Send(0, p);
  }
  std::vector<Delivery> got;
  ch.TakeDeliveries(1'000'000'000, &got);
  ASSERT_EQ(got.size(), 5u);
  const std::int64_t tail_ns = ch.AirtimeNs(1000) + 33;  // airtime + 10 m at c (33 ns)
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].packet.seq, i);
    EXPECT_EQ(got[i].at_ns, static_cast<std::int64_t>(i + 1) * 100'000'000 + tail_ns);
  }
}

TEST(ChannelImpairment, ClearingTheSendersOwnFallsBackToTheDefault) {
  Channel ch(CleanProfile(), 2, 42, {});
  ch.SetPositions(LineUp(2, 10));
  Impairment def;
  def.delay_ms = 10;
  Impairment own;
  own.delay_ms = 300;
  ch.SetImpairment(std::nullopt, def);
  ch.SetImpairment(0, own);
  auto one = [&](std::int64_t t, std::uint64_t seq) {
    Packet p;
    p.from = 0;
    p.to = 1;
    p.seq = seq;
    p.size_bytes = 100;
    p.sent_ns = t;
    ch.Send(t, p);
    std::vector<Delivery> got;
    ch.TakeDeliveries(t + 1'000'000'000, &got);
    EXPECT_EQ(got.size(), 1u);
    return got.empty() ? 0 : (got[0].at_ns - t - ch.AirtimeNs(100)) / 1'000'000;
  };
  EXPECT_EQ(one(0, 1), 300);
  ch.ClearImpairment(0);
  EXPECT_EQ(one(1'000'000'000, 2), 10);
  ch.ClearImpairment(std::nullopt);
  EXPECT_EQ(one(2'000'000'000, 3), 0);
}

TEST(ChannelImpairment, RefusesDistributionsItDoesNotCarryOut) {
  for (const char* name : {"pareto", "paretonormal", "exponential"}) {
    Impairment imp;
    imp.distribution = name;
    const Status s = ValidateImpairment(imp);
    ASSERT_FALSE(s.ok()) << name;
    EXPECT_NE(s.error().message().find(std::string("'") + name + "'"), std::string::npos) << s.error().message();
    EXPECT_NE(s.error().message().find("supported: normal, uniform"), std::string::npos) << s.error().message();
  }
  Impairment ok;
  ok.distribution = "uniform";
  EXPECT_TRUE(ValidateImpairment(ok).ok());
}

TEST(ChannelImpairment, RefusesValuesOutOfRange) {
  Impairment imp;
  imp.loss = 1.5;
  ASSERT_FALSE(ValidateImpairment(imp).ok());
  EXPECT_NE(ValidateImpairment(imp).error().message().find("loss"), std::string::npos);
  imp.loss = 0;
  imp.delay_ms = -1;
  ASSERT_FALSE(ValidateImpairment(imp).ok());
  EXPECT_NE(ValidateImpairment(imp).error().message().find("delay_ms"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::channel
