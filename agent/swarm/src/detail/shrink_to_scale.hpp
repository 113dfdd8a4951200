// ShrinkToScale: a frame finer on the ground than a patch sampler needs is shrunk once, averaging
// (INTER_AREA: no aliasing), so that the sampler's bilinear reads see every pixel. Shared by the
// blob features (blob_features.cpp) and the CNN's patches (candidate_patch.cpp).
#pragma once

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace swarmbox::swarm::detail {

// The image to sample: `bgr` itself when `pixels_per_m` <= `max_px_per_m`, else `bgr` shrunk to
// about `max_px_per_m` in `*small`. `*to_image` gets that image's pixels per input pixel (1 or less).
inline const cv::Mat& ShrinkToScale(const cv::Mat& bgr, double pixels_per_m, double max_px_per_m,
                                    cv::Mat* small, double* to_image) {
  *to_image = 1.0;
  if (pixels_per_m <= max_px_per_m) return bgr;
  const double s = max_px_per_m / pixels_per_m;
  const cv::Size size(std::max(1, static_cast<int>(std::lround(bgr.cols * s))),
                      std::max(1, static_cast<int>(std::lround(bgr.rows * s))));
  cv::resize(bgr, *small, size, 0, 0, cv::INTER_AREA);
  *to_image = static_cast<double>(size.width) / bgr.cols;
  return *small;
}

}  // namespace swarmbox::swarm::detail
