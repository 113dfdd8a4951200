// Synthetic rectified stereo pairs with known disparities, for the matcher's tests.
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace swarmbox::depth::testing {

// A textured plane at disparity d_px (left pixel u shows what right pixel u - d shows) with a
// raised square of its own texture at d_box_px (left columns 141..219, rows 61..139), read noise
// of one level in each view.
struct Pair {
  cv::Mat left, right;
};
inline cv::Mat Texture(int h, int w, double std, cv::RNG& rng) {
  cv::Mat coarse(h / 2, w / 2, CV_32F), fine;
  rng.fill(coarse, cv::RNG::NORMAL, 120.0, std);
  cv::resize(coarse, fine, cv::Size(w, h), 0, 0, cv::INTER_LINEAR);
  return fine;
}
inline Pair MakePair(int d_px, int d_box_px, double texture_std, std::uint64_t seed) {
  cv::RNG rng(seed);
  const int w = 320, h = 200, pad = 64;
  const cv::Mat ground = Texture(h, w + pad, texture_std, rng), box = Texture(h, w + pad, texture_std, rng);
  auto in_box = [](int v, int u) { return v > 60 && v < 140 && u > 140 && u < 220; };
  Pair p;
  p.left.create(h, w, CV_8U);
  p.right.create(h, w, CV_8U);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      // Left u: the box's texture at u, or the ground's at u + pad - d.
      const float l = in_box(v, u) ? box.at<float>(v, u) : ground.at<float>(v, u + pad - d_px);
      // Right u: what left u + d shows, the box where it covers that point.
      const float r = in_box(v, u + d_box_px) ? box.at<float>(v, u + d_box_px) : ground.at<float>(v, u + pad);
      p.left.at<std::uint8_t>(v, u) = cv::saturate_cast<std::uint8_t>(l + rng.gaussian(1.0));
      p.right.at<std::uint8_t>(v, u) = cv::saturate_cast<std::uint8_t>(r + rng.gaussian(1.0));
    }
  }
  return p;
}

}  // namespace swarmbox::depth::testing
