#include "swarmbox/faults/delay_scheduler.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "swarmbox/faults/netem_random.hpp"

namespace swarmbox::faults {
namespace {

// A fake clock: packets arrive every `spacing_us`; returns each packet's hold time [us] in arrival
// order, plus the order in which they were released.
struct Schedule {
  std::vector<std::int64_t> hold_us;
  std::vector<std::uint32_t> release_order;
};

Schedule Simulate(const DelaySettings& settings, std::uint64_t seed, int packets, std::int64_t spacing_us) {
  DelayScheduler s(settings, seed);
  Schedule run;
  run.hold_us.resize(static_cast<std::size_t>(packets));
  std::int64_t now = 0;
  auto release_until = [&](std::int64_t t) {
    while (auto next = s.NextReleaseUs()) {
      if (*next > t) break;
      HeldPacket p = s.PopNext();
      run.hold_us[p.id] = p.release_us - p.admitted_us;
      run.release_order.push_back(p.id);
    }
  };
  for (int i = 0; i < packets; ++i) {
    release_until(now);
    s.Admit(static_cast<std::uint32_t>(i), now);
    now += spacing_us;
  }
  release_until(INT64_MAX);
  return run;
}

double Mean(const std::vector<std::int64_t>& v) {
  double sum = 0;
  for (auto x : v) sum += static_cast<double>(x);
  return sum / static_cast<double>(v.size());
}

double StdDev(const std::vector<std::int64_t>& v) {
  const double m = Mean(v);
  double sum = 0;
  for (auto x : v) sum += (static_cast<double>(x) - m) * (static_cast<double>(x) - m);
  return std::sqrt(sum / static_cast<double>(v.size() - 1));
}

TEST(DelayScheduler, FixedDelayHoldsEveryPacketExactly) {
  DelaySettings s;
  s.delay_us = 50000;
  const Schedule run = Simulate(s, 1, 100, 1000);
  for (auto h : run.hold_us) EXPECT_EQ(h, 50000);
  // No jitter: first in, first out.
  for (std::size_t i = 0; i < run.release_order.size(); ++i) EXPECT_EQ(run.release_order[i], i);
}

TEST(DelayScheduler, UniformJitterStaysWithinBoundsWithTheRightMoments) {
  DelaySettings s;
  s.delay_us = 50000;
  s.jitter_us = 10000;
  const int n = 20000;
  const Schedule run = Simulate(s, 7, n, 100);
  for (auto h : run.hold_us) {
    EXPECT_GE(h, 40000);
    EXPECT_LE(h, 60000);
  }
  // Uniform on [40, 60] ms: mean 50 ms, sd 20/sqrt(12) = 5.774 ms. Standard error of the mean with
  // n = 20,000 is 5.774/sqrt(n) = 0.041 ms: allow 5 standard errors (0.2 ms); the sd within 2%.
  EXPECT_NEAR(Mean(run.hold_us), 50000, 200);
  EXPECT_NEAR(StdDev(run.hold_us), 5774, 0.02 * 5774);
}

TEST(DelayScheduler, NormalJitterHasTheRequestedMeanAndSpread) {
  DelaySettings s;
  s.delay_us = 100000;
  s.jitter_us = 20000;
  s.distribution = DelayDistribution::kNormal;
  const int n = 20000;
  const Schedule run = Simulate(s, 11, n, 100);
  // Normal(100 ms, 20 ms), clamped at 4 sigma like netem's table: standard error of the mean
  // 20/sqrt(20000) = 0.14 ms, allow 5 (0.7 ms); the sd within 3% (its standard error is ~0.5%).
  EXPECT_NEAR(Mean(run.hold_us), 100000, 700);
  EXPECT_NEAR(StdDev(run.hold_us), 20000, 600);
  // About 68.3% within one sigma: the binomial standard error is 0.33%; allow 1.5%.
  const auto within = std::count_if(run.hold_us.begin(), run.hold_us.end(),
                                    [](std::int64_t h) { return std::llabs(h - 100000) <= 20000; });
  EXPECT_NEAR(static_cast<double>(within) / n, 0.6827, 0.015);
}

TEST(DelayScheduler, ParetoJitterIsSkewedToLongDelays) {
  DelaySettings s;
  s.delay_us = 50000;
  s.jitter_us = 10000;
  s.distribution = DelayDistribution::kPareto;
  const Schedule run = Simulate(s, 3, 20000, 100);
  std::vector<std::int64_t> sorted = run.hold_us;
  std::sort(sorted.begin(), sorted.end());
  const auto median = sorted[sorted.size() / 2];
  // netem's pareto table (a = 3, (x - 1.5) * 4/3): the median sits below the mean
  // ((2^(1/3) - 1.5) * 4/3 = -0.32 sigma), the tail reaches the table's +4 sigma clamp.
  EXPECT_NEAR(static_cast<double>(median), 50000 - 0.32 * 10000, 300);
  EXPECT_GT(sorted.back(), 50000 + 3 * 10000);
  EXPECT_GE(sorted.front(), 50000 - 0.67 * 10000 - 1);  // the smallest pareto value is x = 1
}

TEST(DelayScheduler, JitterReordersLikeNetemsTfifo) {
  DelaySettings s;
  s.delay_us = 50000;
  s.jitter_us = 10000;
  const Schedule run = Simulate(s, 5, 1000, 100);  // packets 0.1 ms apart, jitter 10 ms: heavy reordering
  int inversions = 0;
  for (std::size_t i = 1; i < run.release_order.size(); ++i) {
    if (run.release_order[i] < run.release_order[i - 1]) ++inversions;
  }
  EXPECT_GT(inversions, 100);
  // Released in release-time order regardless.
  std::vector<std::int64_t> release_times;
  for (auto id : run.release_order) release_times.push_back(static_cast<std::int64_t>(id) * 100 + run.hold_us[id]);
  EXPECT_TRUE(std::is_sorted(release_times.begin(), release_times.end()));
}

TEST(DelayScheduler, ReorderSendsTheFractionAtOnce) {
  DelaySettings s;
  s.delay_us = 10000;
  s.reorder = 0.25;
  const int n = 10000;
  DelayScheduler sched(s, 99);
  int immediate = 0;
  for (int i = 0; i < n; ++i) {
    const std::int64_t now = i * 1000;
    if (sched.Admit(static_cast<std::uint32_t>(i), now) == now) ++immediate;
  }
  // Binomial(10000, 0.25): standard error 0.43%; allow 4 of them (1.75%).
  EXPECT_NEAR(static_cast<double>(immediate) / n, 0.25, 0.0175);
  EXPECT_EQ(sched.reordered(), static_cast<std::uint64_t>(immediate));
}

TEST(DelayScheduler, ReorderGapDelaysTheFirstGapMinusOnePackets) {
  DelaySettings s;
  s.delay_us = 10000;
  s.reorder = 1.0;  // with gap 5: every 5th packet goes at once, the others wait
  s.reorder_gap = 5;
  DelayScheduler sched(s, 1);
  std::vector<bool> early;
  for (int i = 0; i < 15; ++i) early.push_back(sched.Admit(static_cast<std::uint32_t>(i), i) == i);
  const std::vector<bool> expected = {false, false, false, false, true, false, false, false, false, true,
                                      false, false, false, false, true};
  EXPECT_EQ(early, expected);
}

TEST(DelayScheduler, SameSeedSameSchedule) {
  DelaySettings s;
  s.delay_us = 30000;
  s.jitter_us = 5000;
  s.distribution = DelayDistribution::kParetoNormal;
  s.correlation = 0.3;
  EXPECT_EQ(Simulate(s, 42, 500, 200).hold_us, Simulate(s, 42, 500, 200).hold_us);
  EXPECT_NE(Simulate(s, 42, 500, 200).hold_us, Simulate(s, 43, 500, 200).hold_us);
}

TEST(DelayScheduler, CorrelationMakesConsecutiveDelaysAlike) {
  DelaySettings s;
  s.delay_us = 50000;
  s.jitter_us = 10000;
  auto lag1 = [](const std::vector<std::int64_t>& v) {
    const double m = Mean(v);
    double num = 0;
    double den = 0;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const double d = static_cast<double>(v[i]) - m;
      den += d * d;
      if (i > 0) num += d * (static_cast<double>(v[i - 1]) - m);
    }
    return num / den;
  };
  const int n = 10000;
  const double independent = lag1(Simulate(s, 8, n, 100).hold_us);
  s.correlation = 0.75;
  const double correlated = lag1(Simulate(s, 8, n, 100).hold_us);
  // netem's get_crandom is an AR(1) on the uniform draw, next = (1 - rho) u + rho last, and the
  // uniform jitter is linear in it: lag-1 autocorrelation rho. Its standard error with n = 10,000
  // is about 1/sqrt(n) = 0.01; allow 5 of them.
  EXPECT_NEAR(independent, 0.0, 0.05);
  EXPECT_NEAR(correlated, 0.75, 0.05);
}

TEST(NetemRandom, QuantilesMatchTheirDistributions) {
  EXPECT_DOUBLE_EQ(DistributionQuantile(DelayDistribution::kUniform, 0.75), 0.5);
  EXPECT_NEAR(DistributionQuantile(DelayDistribution::kNormal, 0.5), 0.0, 1e-9);
  EXPECT_NEAR(DistributionQuantile(DelayDistribution::kNormal, 0.841344746), 1.0, 1e-6);
  EXPECT_NEAR(DistributionQuantile(DelayDistribution::kNormal, 0.001), -3.090232, 1e-5);
  // Pareto a = 3 at u = 7/8: x = 2, (2 - 1.5) * 4/3 = 2/3.
  EXPECT_NEAR(DistributionQuantile(DelayDistribution::kPareto, 0.875), 2.0 / 3.0, 1e-9);
  // Clamped to the table's range.
  EXPECT_NEAR(DistributionQuantile(DelayDistribution::kPareto, 1.0 - 1e-12), 32767.0 / 8192.0, 1e-9);
  EXPECT_NEAR(DistributionQuantile(DelayDistribution::kParetoNormal, 0.875),
              (3.0 * (2.0 / 3.0) + DistributionQuantile(DelayDistribution::kNormal, 0.875)) / 4.0, 1e-9);
}

TEST(NetemRandom, NegativeDelaysAreClampedToZero) {
  EXPECT_EQ(SampleDelayUs(1000, 5000, DelayDistribution::kUniform, 0), 0);
  EXPECT_EQ(SampleDelayUs(1000, 0, DelayDistribution::kNormal, 12345), 1000);
}

TEST(NetemRandom, FullCorrelationRepeatsTheFirstDraw) {
  std::mt19937 rng(1);
  CorrelatedUniform u(1.0, rng);
  const auto first = u.Next();
  for (int i = 0; i < 10; ++i) EXPECT_NEAR(static_cast<double>(u.Next()), static_cast<double>(first), 2.0);
}

}  // namespace
}  // namespace swarmbox::faults
