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

}  // namespace
}  // namespace swarmbox::swarm
