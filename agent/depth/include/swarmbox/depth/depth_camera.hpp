// DepthCamera: the OAK-D Pro as the agent sees it: a rectified pair exposed at a simulated time
// is matched (StereoMatcher, what the device's chip does), summarised (DepthSummary), and handed
// out only once the device's latency has passed (DeviceLatency, 30-50 ms of simulated time).
//
//   DepthCamera camera({.latency_min_ms = 30, .latency_max_ms = 50}, /*seed=*/drone_seed);
//   camera.OnPair(frame_time_ns, left, right, focal_px, baseline_m);   // at the exposure
//   while (auto f = camera.Poll(step_time_ns)) Publish(ToMessage(drone, *f));  // each step
//
// Pure: simulated time only, no I/O. The depth image travels with its summary (for the mission on
// the same drone); the bus carries the summary (depth_message.hpp).
#pragma once

#include <cstdint>
#include <optional>

#include <opencv2/core.hpp>

#include "swarmbox/depth/depth_summary.hpp"
#include "swarmbox/depth/device_latency.hpp"
#include "swarmbox/depth/stereo_matcher.hpp"

namespace swarmbox::depth {

struct DepthCameraConfig {
  MatchConfig match;
  double latency_min_ms = 30;
  double latency_max_ms = 50;
  int grid_cols = 8;
  int grid_rows = 5;
};

struct DepthFrame {
  std::int64_t capture_ns = 0;   // exposure
  std::int64_t release_ns = 0;   // when the host has it: capture + the device's latency
  cv::Mat depth_m;               // CV_32F, 0 = no depth
  DepthSummary summary;
};

class DepthCamera {
 public:
  DepthCamera(const DepthCameraConfig& config, std::uint64_t seed);

  void OnPair(std::int64_t capture_ns, const cv::Mat& left, const cv::Mat& right, double focal_px,
              double baseline_m);
  // The oldest frame released at or before now_ns, if any.
  std::optional<DepthFrame> Poll(std::int64_t now_ns);

 private:
  DepthCameraConfig config_;
  StereoMatcher matcher_;
  DeviceLatency<DepthFrame> latency_;
};

}  // namespace swarmbox::depth
