// DepthSummary: what an agent tells the others (and its own mission) about a depth image in a few
// numbers: how much of it has depth, the median and the nearest depths, and a coarse grid of
// median depths (the ground's shape under the drone: heaps, boxes, a slope).
//
//   DepthSummary s = Summarize(depth_m, /*grid_cols=*/8, /*grid_rows=*/5);
//
// Pure. Depth 0 (or not finite) = no depth; a grid cell with no depth holds 0.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace swarmbox::depth {

struct DepthSummary {
  double fill_rate = 0;         // share of the image's pixels with depth [0, 1]
  double median_m = 0;          // over the pixels with depth (0 when none)
  double near_p5_m = 0;         // 5th percentile: the nearest things, robust to single outliers
  int grid_cols = 0;
  int grid_rows = 0;
  std::vector<float> grid_m;    // grid_rows x grid_cols medians, row-major (image rows top down)
};

DepthSummary Summarize(const cv::Mat& depth_m, int grid_cols, int grid_rows);

}  // namespace swarmbox::depth
