// StereoMatcher: depth from a rectified stereo pair with OpenCV's semi-global block matching
// (cv::StereoSGBM), as the OAK-D Pro computes it on its own chip and the agent gets it.
//
//   StereoMatcher matcher({.num_disparities = 64});
//   cv::Mat depth_m;                                   // CV_32F, 0 where there is no depth
//   matcher.Compute(left, right, focal_px, baseline_m, &depth_m);
//
// Depth Z = focal_px * baseline_m / d for a disparity d > 0 (sub-pixel, 1/16 px); pixels the
// matcher rejects (no unique match, speckles, the left band of num_disparities columns the
// right view cannot see) are 0. Rectified means: same focal length and rows, the right camera
// baseline_m to the right of the left one (swarmbox::physics::StereoRenderer draws pairs so).
// Pure: no clock, no I/O; not thread-safe (scratch disparity image); one matcher per thread.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/calib3d.hpp>

namespace swarmbox::depth {

// The depth range the agent trusts from the pair [m]: the OAK-D Pro's projector reaches 15 m, and
// SGBM's median error there is already 1.3 m (2.9 m at 20 m: BENCHMARKS.md "stereo").
// ClearanceConfig and DepthSurfaceConfig ignore depth beyond it.
inline constexpr double kTrustedDepthRangeM = 15.0;

// cv::StereoSGBM parameters (OpenCV's names). P1/P2 are 8 and 32 x block_size^2 (OpenCV's
// suggested values for one channel).
struct MatchConfig {
  int num_disparities = 64;   // multiple of 16: the largest disparity searched [px]
  int block_size = 5;         // odd
  int uniqueness_ratio = 10;  // [%] the best match beats the second by this much
  int speckle_window = 100;   // [px] disparity blobs smaller than this are removed
  int speckle_range = 2;      // [px] disparity variation allowed within a blob
  int disp12_max_diff = 1;    // [px] left-right consistency check
  bool three_way = true;      // MODE_SGBM_3WAY: OpenCV's faster variant
};

class StereoMatcher {
 public:
  explicit StereoMatcher(const MatchConfig& config = {});

  // `left`, `right`: CV_8U, same size. Writes `depth_m` (CV_32F, left image's pixels).
  void Compute(const cv::Mat& left, const cv::Mat& right, double focal_px, double baseline_m, cv::Mat* depth_m);

  const MatchConfig& config() const { return config_; }

 private:
  MatchConfig config_;
  cv::Ptr<cv::StereoSGBM> sgbm_;
  cv::Mat disparity_;  // CV_16S, 16 x disparity
};

}  // namespace swarmbox::depth
