#include "swarmbox/depth/depth_camera.hpp"

namespace swarmbox::depth {

DepthCamera::DepthCamera(const DepthCameraConfig& config, std::uint64_t seed)
    : config_(config), matcher_(config.match), latency_(config.latency_min_ms, config.latency_max_ms, seed) {}

void DepthCamera::OnPair(std::int64_t capture_ns, const cv::Mat& left, const cv::Mat& right, double focal_px,
                         double baseline_m) {
  DepthFrame frame;
  frame.capture_ns = capture_ns;
  matcher_.Compute(left, right, focal_px, baseline_m, &frame.depth_m);
  frame.summary = Summarize(frame.depth_m, config_.grid_cols, config_.grid_rows);
  // The release time is known once queued; it is written into the frame when it leaves.
  latency_.Push(capture_ns, std::move(frame));
}

std::optional<DepthFrame> DepthCamera::Poll(std::int64_t now_ns) {
  const std::optional<std::int64_t> release = latency_.NextRelease();
  auto frame = latency_.Pop(now_ns);
  if (frame) frame->release_ns = *release;
  return frame;
}

}  // namespace swarmbox::depth
