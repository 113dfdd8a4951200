#include "depth_host.hpp"

#include <utility>

#include "swarmbox/bus/topics.hpp"
#include "swarmbox/depth/depth_message.hpp"

namespace swarmbox::agent {

namespace {

depth::DepthCameraConfig CameraConfigFor(const airframe::StereoSpec& spec) {
  depth::DepthCameraConfig c;
  c.match.num_disparities = spec.num_disparities;
  c.latency_min_ms = spec.latency_min_ms;
  c.latency_max_ms = spec.latency_max_ms;
  return c;
}

}  // namespace

Result<std::unique_ptr<DepthHost>> DepthHost::Create(bus::Participant& sim, DepthHostConfig config) {
  auto pairs = sim.CreateSubscriber<bus::CameraImage>(bus::StereoTopic(config.drone), bus::Qos::kLockstep);
  if (!pairs) return pairs.error().Context("subscribing to the stereo pair");
  auto summaries = sim.CreatePublisher<bus::DepthSummary>(bus::kDepthTopic, bus::Qos::kState);
  if (!summaries) return summaries.error().Context("publishing depth summaries");
  return std::unique_ptr<DepthHost>(new DepthHost(std::move(config), std::move(*pairs), std::move(*summaries)));
}

DepthHost::DepthHost(DepthHostConfig config, std::unique_ptr<bus::Subscriber<bus::CameraImage>> pairs,
                     std::unique_ptr<bus::Publisher<bus::DepthSummary>> summaries)
    : config_(std::move(config)),
      pairs_sub_(std::move(pairs)),
      summaries_(std::move(summaries)),
      camera_(CameraConfigFor(config_.spec), config_.seed) {}

FrameWait DepthHost::TakePairs(const bus::SensorSample& msg, const bus::Pose& body_estimate) {
  const FrameWait w =
      TakeStepFrames(*pairs_sub_, msg.sim_time_ns, msg.stereo_frame, config_.pair_timeout, config_.stop, &frames_);
  for (std::size_t i = 0; i < frames_.count; ++i) OnPair(frames_.images[i], body_estimate);
  return w;
}

void DepthHost::OnPair(const bus::CameraImage& image, const bus::Pose& body_estimate) {
  // The pair's layout (bus::StereoTopic): mono8, left | right, each spec width x height.
  const int w = config_.spec.width_px;
  const int h = config_.spec.height_px;
  if (image.encoding != "mono8" || image.width_px != static_cast<std::uint32_t>(2 * w) ||
      image.height_px != static_cast<std::uint32_t>(h) || image.row_stride_bytes < image.width_px ||
      image.data.size() < static_cast<std::size_t>(image.height_px) * image.row_stride_bytes) {
    ++rejected_;
    return;
  }
  ++pairs_;
  // Read-only views of the message's buffer; DepthCamera matches them at once.
  const cv::Mat both(h, 2 * w, CV_8UC1, const_cast<std::uint8_t*>(image.data.data()), image.row_stride_bytes);
  const cv::Mat left = both.colRange(0, w);
  const cv::Mat right = both.colRange(w, 2 * w);
  // The camera's pose as the drone knows it: its own estimate at the exposure's step (the server's
  // true pose in the message is for recordings), through the pair's mount on the body.
  const depth::StereoMount mount{.offset_body_m = {config_.spec.offset_m.x, config_.spec.offset_m.y,
                                                   config_.spec.offset_m.z},
                                 .baseline_m = config_.spec.baseline_m};
  exposures_.push_back({.capture_ns = image.sim_time_ns,
                        .camera_pose = depth::LeftCameraPose(body_estimate, mount),
                        .intrinsics = {.focal_px = image.intrinsics.fx_px,
                                       .cx_px = image.intrinsics.cx_px,
                                       .cy_px = image.intrinsics.cy_px}});
  camera_.OnPair(image.sim_time_ns, left, right, image.intrinsics.fx_px, config_.spec.baseline_m);
}

int DepthHost::Release(std::int64_t now_ns) {
  int released = 0;
  while (std::optional<depth::DepthFrame> f = camera_.Poll(now_ns)) {
    // Frames leave in capture order: the front exposure is this one's.
    while (!exposures_.empty() && exposures_.front().capture_ns < f->capture_ns) exposures_.pop_front();
    Exposure e = exposures_.empty() ? Exposure{} : exposures_.front();
    if (!exposures_.empty()) exposures_.pop_front();
    (void)summaries_->Publish(depth::ToMessage(config_.drone, *f, e.camera_pose));
    latest_ = Frame{.frame = std::move(*f), .camera_pose = e.camera_pose, .intrinsics = e.intrinsics};
    ++released;
  }
  return released;
}

}  // namespace swarmbox::agent
