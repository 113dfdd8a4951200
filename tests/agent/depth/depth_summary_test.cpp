#include "swarmbox/depth/depth_summary.hpp"

#include <gtest/gtest.h>

namespace swarmbox::depth {
namespace {

TEST(DepthSummary, FillMedianNearAndGrid) {
  // 40 x 20: left half 10 m, right half 4 m, the top-left quarter without depth.
  cv::Mat depth(20, 40, CV_32F, cv::Scalar(10.0f));
  depth(cv::Rect(20, 0, 20, 20)).setTo(4.0f);
  depth(cv::Rect(0, 0, 20, 10)).setTo(0.0f);
  const DepthSummary s = Summarize(depth, 2, 2);
  EXPECT_DOUBLE_EQ(s.fill_rate, 0.75);
  EXPECT_FLOAT_EQ(static_cast<float>(s.median_m), 4.0f);  // 400 px at 4 m, 200 at 10 m
  EXPECT_FLOAT_EQ(static_cast<float>(s.near_p5_m), 4.0f);
  ASSERT_EQ(s.grid_m.size(), 4u);
  EXPECT_FLOAT_EQ(s.grid_m[0], 0.0f);   // top-left: no depth
  EXPECT_FLOAT_EQ(s.grid_m[1], 4.0f);
  EXPECT_FLOAT_EQ(s.grid_m[2], 10.0f);
  EXPECT_FLOAT_EQ(s.grid_m[3], 4.0f);
}

TEST(DepthSummary, EmptyImageHasNoDepth) {
  const DepthSummary s = Summarize(cv::Mat::zeros(10, 10, CV_32F), 3, 3);
  EXPECT_EQ(s.fill_rate, 0.0);
  EXPECT_EQ(s.median_m, 0.0);
  EXPECT_EQ(s.grid_m.size(), 9u);
}

}  // namespace
}  // namespace swarmbox::depth
