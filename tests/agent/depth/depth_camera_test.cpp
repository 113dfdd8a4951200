#include "swarmbox/depth/depth_camera.hpp"

#include <gtest/gtest.h>

#include "swarmbox/depth/depth_message.hpp"
#include "synthetic_pair.hpp"

namespace swarmbox::depth {
namespace {

constexpr std::int64_t kMs = 1'000'000;

TEST(DepthCamera, DepthArrivesOnlyAfterTheDeviceLatencyOfSimulatedTime) {
  const testing::Pair pair = testing::MakePair(8, 16, 25, 4);
  DepthCamera camera({}, /*seed=*/5);
  const std::int64_t t0 = 10'000 * kMs;
  camera.OnPair(t0, pair.left, pair.right, 441.0, 0.075);
  EXPECT_FALSE(camera.Poll(t0).has_value());
  EXPECT_FALSE(camera.Poll(t0 + 30 * kMs - 1).has_value());
  auto frame = camera.Poll(t0 + 50 * kMs);
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(frame->capture_ns, t0);
  EXPECT_GE(frame->release_ns, t0 + 30 * kMs);
  EXPECT_LE(frame->release_ns, t0 + 50 * kMs);
  // The plane at d = 8 px is 441 * 0.075 / 8 = 4.13 m; the box (d = 16) 2.07 m is the nearest.
  EXPECT_GT(frame->summary.fill_rate, 0.6);
  EXPECT_NEAR(frame->summary.median_m, 4.13, 0.1);
  EXPECT_NEAR(frame->summary.near_p5_m, 2.07, 0.1);
  EXPECT_FALSE(camera.Poll(t0 + 60 * kMs).has_value());
}

TEST(DepthCamera, TheBusMessageCarriesTheSummaryAndBothTimes) {
  DepthFrame frame;
  frame.capture_ns = 100;
  frame.release_ns = 40'000'100;
  frame.summary = {0.5, 7.0, 3.0, 2, 1, {6.5f, 7.5f}};
  bus::Pose pose;
  pose.position_enu_m = {1, 2, 10};
  const bus::DepthSummary m = ToMessage("scout_1", frame, pose);
  EXPECT_EQ(m.drone, "scout_1");
  EXPECT_EQ(m.capture_ns, 100);
  EXPECT_EQ(m.sim_time_ns, 40'000'100);
  EXPECT_DOUBLE_EQ(m.fill_rate, 0.5);
  EXPECT_DOUBLE_EQ(m.median_m, 7.0);
  EXPECT_DOUBLE_EQ(m.near_p5_m, 3.0);
  EXPECT_EQ(m.grid_cols, 2u);
  EXPECT_EQ(m.grid_rows, 1u);
  EXPECT_EQ(m.grid_m, (std::vector<double>{6.5, 7.5}));
  EXPECT_EQ(m.camera_pose, pose);
}

}  // namespace
}  // namespace swarmbox::depth
