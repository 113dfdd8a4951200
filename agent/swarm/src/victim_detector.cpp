#include "swarmbox/swarm/victim_detector.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <cstdint>

#include <opencv2/imgproc.hpp>

#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {

VictimDetector::VictimDetector(const VictimDetectorParams& params)
    : params_(params), kernel_(cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3))) {
  SWARMBOX_CHECK(params_.min_area_ratio > 0 && params_.min_area_ratio < params_.full_size_ratio);
  SWARMBOX_CHECK(params_.full_size_ratio <= params_.full_size_max_ratio &&
                 params_.full_size_max_ratio < params_.max_area_ratio);
}

void VictimDetector::Detect(const cv::Mat& bgr, double pixels_per_m, std::vector<ImageBlob>* out) {
  SWARMBOX_CHECK(pixels_per_m > 0);
  const double expected = params_.person_area_m2 * pixels_per_m * pixels_per_m;
  DetectImpl(bgr, [expected](const Eigen::Vector2d&) { return expected; }, out);
}

void VictimDetector::Detect(const cv::Mat& bgr, const PinholeIntrinsics& k, const OpticalPose& pose,
                            double ground_z_m, std::vector<ImageBlob>* out) {
  SWARMBOX_CHECK(k.fx_px > 0 && k.fy_px > 0);
  const double f2 = k.fx_px * k.fy_px;
  const double area = params_.person_area_m2;
  DetectImpl(
      bgr,
      [&](const Eigen::Vector2d& px) {
        const Eigen::Vector3d ray = PixelRay(px, k, pose);
        const std::optional<Eigen::Vector3d> g = PixelToGround(px, k, pose, ground_z_m);
        if (!g) return 0.0;  // no ground there: no person either
        const double range = (*g - pose.position_m).norm();
        // Projected area ~ A cos(incidence) / range^2 in steradians, times f^2 / cos^3(off-axis)
        // for the pixel footprint of that solid angle.
        const Eigen::Vector3d axis = pose.rotation * Eigen::Vector3d::UnitZ();
        const double off_axis = std::max(0.05, ray.dot(axis));
        return area * std::abs(ray.z()) * f2 / (range * range) / (off_axis * off_axis * off_axis);
      },
      out);
}

template <typename ExpectedAreaFn>
void VictimDetector::DetectImpl(const cv::Mat& bgr, ExpectedAreaFn expected_area_px,
                                std::vector<ImageBlob>* out) {
  SWARMBOX_CHECK(bgr.type() == CV_8UC3);
  out->clear();
  const VictimDetectorParams& k = params_;
  mask_.create(bgr.size(), CV_8UC1);
  for (int r = 0; r < bgr.rows; ++r) {
    const auto* px = bgr.ptr<cv::Vec3b>(r);
    auto* m = mask_.ptr<std::uint8_t>(r);
    for (int c = 0; c < bgr.cols; ++c) {
      const int b = px[c][0], g = px[c][1], red = px[c][2];
      m[c] = (red >= k.min_red && red - b >= k.min_red_minus_blue && red - g >= k.min_red_minus_green)
                 ? 255 : 0;
    }
  }
  cv::morphologyEx(mask_, closed_, cv::MORPH_CLOSE, kernel_);
  const int n = cv::connectedComponentsWithStats(closed_, labels_, stats_, centroids_, 8, CV_32S);
  for (int i = 1; i < n; ++i) {
    const int area = stats_.at<int>(i, cv::CC_STAT_AREA);
    if (area < k.min_area_px) continue;
    const int x = stats_.at<int>(i, cv::CC_STAT_LEFT), y = stats_.at<int>(i, cv::CC_STAT_TOP);
    const int w = stats_.at<int>(i, cv::CC_STAT_WIDTH), h = stats_.at<int>(i, cv::CC_STAT_HEIGHT);
    ImageBlob blob;
    blob.centroid_px = {centroids_.at<double>(i, 0), centroids_.at<double>(i, 1)};
    const double expected = expected_area_px(blob.centroid_px);
    if (!(expected > 0)) continue;
    blob.area_px = area;
    blob.expected_area_px = expected;
    blob.partial = x <= k.border_px || y <= k.border_px || x + w >= bgr.cols - k.border_px ||
                   y + h >= bgr.rows - k.border_px;
    const double ratio = area / expected;
    if (ratio > k.max_area_ratio) continue;
    if (!blob.partial && ratio < k.min_area_ratio) continue;
    if (ratio < k.full_size_ratio) {
      blob.size_score = blob.partial ? ratio / k.full_size_ratio
                                     : (ratio - k.min_area_ratio) / (k.full_size_ratio - k.min_area_ratio);
    } else if (ratio <= k.full_size_max_ratio) {
      blob.size_score = 1.0;
    } else {
      blob.size_score = (k.max_area_ratio - ratio) / (k.max_area_ratio - k.full_size_max_ratio);
    }
    // Colour: mean R - B over the blob's thresholded pixels, scaled from the threshold to 200.
    double sum_rb = 0;
    int count = 0;
    for (int r = y; r < y + h; ++r) {
      const auto* px = bgr.ptr<cv::Vec3b>(r);
      const auto* lab = labels_.ptr<int>(r);
      const auto* m = mask_.ptr<std::uint8_t>(r);
      for (int c = x; c < x + w; ++c) {
        if (lab[c] != i || m[c] == 0) continue;
        sum_rb += px[c][2] - px[c][0];
        ++count;
      }
    }
    const double mean_rb = count > 0 ? sum_rb / count : 0.0;
    blob.colour_score = std::clamp((mean_rb - k.min_red_minus_blue) / (200.0 - k.min_red_minus_blue), 0.0, 1.0);
    blob.confidence = 0.5 + 0.49 * std::clamp(blob.size_score, 0.0, 1.0) * blob.colour_score;
    if (blob.partial) blob.confidence = std::min(blob.confidence, k.partial_confidence_cap);
    out->push_back(blob);
  }
}

}  // namespace swarmbox::swarm
