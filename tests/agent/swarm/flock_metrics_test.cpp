// Flock metrics on hand-made snapshots (definitions in flock_metrics.hpp).
#include "swarmbox/swarm/flock_metrics.hpp"

#include <vector>

#include <gtest/gtest.h>

namespace swarmbox::swarm {
namespace {

using V = Eigen::Vector3d;

TEST(FlockMetrics, AlignedWellSpacedLineIsSafeOrderedAndUnited) {
  const std::vector<V> p = {V(0, 0, 10), V(5, 0, 10), V(10, 0, 10)};
  const std::vector<V> v = {V(1, 0, 0), V(2, 0, 0), V(1, 0, 0)};
  const FlockMetrics m = ComputeFlockMetrics(p, v, {.separation_m = 3, .link_range_m = 6});
  EXPECT_DOUBLE_EQ(m.safety, 1.0);
  EXPECT_NEAR(m.order, 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(m.union_, 1.0);
  EXPECT_EQ(m.components, 1);
  EXPECT_NEAR(m.min_distance_m, 5.0, 1e-12);
  EXPECT_NEAR(m.max_nearest_m, 5.0, 1e-12);
}

TEST(FlockMetrics, ClosePairLowersSafetyAndOpposedVelocitiesLowerOrder) {
  const std::vector<V> p = {V(0, 0, 0), V(1, 0, 0), V(100, 0, 0)};
  const std::vector<V> v = {V(1, 0, 0), V(-1, 0, 0), V(1, 0, 0)};
  const FlockMetrics m = ComputeFlockMetrics(p, v, {.separation_m = 3, .link_range_m = 10});
  EXPECT_NEAR(m.safety, 2.0 / 3.0, 1e-12);           // 1 of 3 pairs too close
  EXPECT_NEAR(m.order, (-1.0 + 1.0 - 1.0) / 3.0, 1e-12);
  EXPECT_EQ(m.components, 2);
  EXPECT_NEAR(m.union_, 1.0 - 1.0 / 2.0, 1e-12);     // 1 - (C-1)/(N-1)
}

RosterEntry Entry(std::string name, double age_s, double x, double y) {
  RosterEntry e;
  e.name = std::move(name);
  e.age_s = age_s;
  e.position_m = Eigen::Vector2d(x, y);
  return e;
}

TEST(FlockMetricsLog, OncePerSimulatedSecondWithVelocitiesFromTheWordsPositions) {
  FlockMetricsLog log({.separation_m = 3, .link_range_m = 20});
  // Given two members heard at t (age 0) moving east at 2 m/s, 10 m apart,
  std::vector<RosterEntry> roster = {Entry("a", 0, 0, 0), Entry("b", 0, 0, 10)};
  // When the leader samples at 10.0 s, its first line goes out at once: nobody has a velocity yet.
  auto first = log.Sample(10.0, "a", roster);
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->str(),
            "t=10.000 node=a event=flock_metrics members=2 order=0.000 safety=1.000 union=1.000 components=1 "
            "min_m=10.00 mean_nearest_m=10.00");
  // Then nothing until a simulated second has passed (the caller steps every 0.1 s).
  roster = {Entry("a", 0, 1, 0), Entry("b", 0, 1, 10)};
  EXPECT_FALSE(log.Sample(10.5, "a", roster).has_value());
  // And at 11.0 s both moved 2 m east in 1 s of their words' time: aligned, order 1.
  roster = {Entry("a", 0, 2, 0), Entry("b", 0, 2, 10)};
  auto second = log.Sample(11.0, "a", roster);
  ASSERT_TRUE(second.has_value());
  EXPECT_NE(second->str().find(" order=1.000 "), std::string::npos) << second->str();
  EXPECT_NE(second->str().find("t=11.000 "), std::string::npos);
}

TEST(FlockMetricsLog, AStaleWordKeepsItsVelocityAndASilentMemberIsLeftOut) {
  FlockMetricsLog log({.separation_m = 3, .link_range_m = 20}, 1.0, 6.0);
  std::vector<RosterEntry> roster = {Entry("a", 0, 0, 0), Entry("b", 0, 0, 2), Entry("c", 0, 50, 0)};
  ASSERT_TRUE(log.Sample(0.0, "a", roster));
  // b's word at 0.5 s (age 0.5 at 1.0 s) moved 1 m north in 0.5 s: 2 m/s north; a east.
  roster = {Entry("a", 0, 1, 0), Entry("b", 0.5, 0, 3), Entry("c", 0, 50, 0)};
  auto line = log.Sample(1.0, "a", roster);
  ASSERT_TRUE(line);
  // Pairs: a-b orthogonal (0), a-c and b-c with the still c (0): order 0; a-b 3.16 m apart: safe;
  // c 50 m away: two groups of three, union 1 - 1/2.
  EXPECT_NE(line->str().find("members=3 order=0.000 safety=1.000 union=0.500 components=2"), std::string::npos)
      << line->str();
  // c silent for 7 s (> 6 s): left out; fewer than two members fresh gives no line.
  roster = {Entry("a", 0, 2, 0), Entry("b", 8, 0, 3), Entry("c", 7, 50, 0)};
  EXPECT_FALSE(log.Sample(2.0, "a", roster).has_value());
  roster = {Entry("a", 0, 3, 0), Entry("b", 0, 3, 4), Entry("c", 7, 50, 0)};
  line = log.Sample(3.0, "a", roster);
  ASSERT_TRUE(line);
  EXPECT_NE(line->str().find("members=2 "), std::string::npos) << line->str();
}

}  // namespace
}  // namespace swarmbox::swarm
