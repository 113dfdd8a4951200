#include "swarmbox/depth/stereo_matcher.hpp"

#include "synthetic_pair.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace swarmbox::depth {
namespace {

using testing::MakePair;
using testing::Pair;

constexpr double kFocalPx = 441.0;
constexpr double kBaselineM = 0.075;

// Fill and median relative error over a region, against the depth of disparity d.
struct Score {
  double fill, median_rel_err;
};
Score ScoreRegion(const cv::Mat& depth, const cv::Rect& roi, double d_px) {
  const double truth = kFocalPx * kBaselineM / d_px;
  std::vector<double> err;
  int n = 0;
  for (int v = roi.y; v < roi.y + roi.height; ++v) {
    for (int u = roi.x; u < roi.x + roi.width; ++u) {
      ++n;
      const float z = depth.at<float>(v, u);
      if (z > 0) err.push_back(std::abs(z - truth) / truth);
    }
  }
  if (err.empty()) return {0, 1e9};
  std::nth_element(err.begin(), err.begin() + static_cast<std::ptrdiff_t>(err.size() / 2), err.end());
  return {static_cast<double>(err.size()) / n, err[err.size() / 2]};
}

TEST(StereoMatcher, TexturedPlaneAndBoxGiveTheirDepths) {
  const Pair p = MakePair(/*d_px=*/8, /*d_box_px=*/16, /*texture_std=*/25, 1);
  StereoMatcher matcher;
  cv::Mat depth;
  matcher.Compute(p.left, p.right, kFocalPx, kBaselineM, &depth);
  ASSERT_EQ(depth.type(), CV_32F);
  // Ground: d = 8 px -> 4.13 m; box: d = 16 px -> 2.07 m.
  const Score ground = ScoreRegion(depth, cv::Rect(80, 10, 50, 40), 8);
  const Score box = ScoreRegion(depth, cv::Rect(160, 75, 40, 50), 16);
  EXPECT_GT(ground.fill, 0.9);
  EXPECT_LT(ground.median_rel_err, 0.02);
  EXPECT_GT(box.fill, 0.9);
  EXPECT_LT(box.median_rel_err, 0.02);
  // The left band of num_disparities columns has no match.
  EXPECT_EQ(cv::countNonZero(depth(cv::Rect(0, 0, 60, depth.rows))), 0);
}

TEST(StereoMatcher, TexturelessPairHasLittleDepth) {
  const Pair p = MakePair(8, 8, /*texture_std=*/0, 2);  // flat grey plus read noise
  StereoMatcher matcher;
  cv::Mat depth;
  matcher.Compute(p.left, p.right, kFocalPx, kBaselineM, &depth);
  const Score all = ScoreRegion(depth, cv::Rect(70, 0, 250, 200), 8);
  EXPECT_LT(all.fill, 0.2);
}

}  // namespace
}  // namespace swarmbox::depth
