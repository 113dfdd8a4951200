#include "swarmbox/depth/stereo_matcher.hpp"

namespace swarmbox::depth {

StereoMatcher::StereoMatcher(const MatchConfig& config) : config_(config) {
  CV_Assert(config.num_disparities >= 16 && config.num_disparities % 16 == 0);
  CV_Assert(config.block_size >= 1 && config.block_size % 2 == 1);
  const int area = config.block_size * config.block_size;
  sgbm_ = cv::StereoSGBM::create(0, config.num_disparities, config.block_size, 8 * area, 32 * area,
                                 config.disp12_max_diff, 0, config.uniqueness_ratio, config.speckle_window,
                                 config.speckle_range,
                                 config.three_way ? cv::StereoSGBM::MODE_SGBM_3WAY : cv::StereoSGBM::MODE_SGBM);
}

void StereoMatcher::Compute(const cv::Mat& left, const cv::Mat& right, double focal_px, double baseline_m,
                            cv::Mat* depth_m) {
  CV_Assert(left.type() == CV_8U && right.type() == CV_8U && left.size() == right.size());
  sgbm_->compute(left, right, disparity_);
  depth_m->create(left.size(), CV_32F);
  const float fb16 = static_cast<float>(focal_px * baseline_m * 16.0);
  for (int v = 0; v < disparity_.rows; ++v) {
    const auto* d = disparity_.ptr<std::int16_t>(v);
    auto* z = depth_m->ptr<float>(v);
    for (int u = 0; u < disparity_.cols; ++u) z[u] = d[u] > 0 ? fb16 / static_cast<float>(d[u]) : 0.0f;
  }
}

}  // namespace swarmbox::depth
