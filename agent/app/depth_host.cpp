#include "depth_host.hpp"

#include <cmath>
#include <limits>
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
  auto images = sim.CreatePublisher<bus::CameraImage>(bus::DepthImageTopic(config.drone), bus::Qos::kLockstep);
  if (!images) return images.error().Context("publishing depth images");
  return std::unique_ptr<DepthHost>(
      new DepthHost(std::move(config), std::move(*pairs), std::move(*summaries), std::move(*images)));
}

DepthHost::DepthHost(DepthHostConfig config, std::unique_ptr<bus::Subscriber<bus::CameraImage>> pairs,
                     std::unique_ptr<bus::Publisher<bus::DepthSummary>> summaries,
                     std::unique_ptr<bus::Publisher<bus::CameraImage>> images)
    : config_(std::move(config)),
      pairs_sub_(std::move(pairs)),
      summaries_(std::move(summaries)),
      images_(std::move(images)),
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
                        .step = image.step,
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
    latest_ = Frame{.frame = std::move(*f), .camera_pose = e.camera_pose, .intrinsics = e.intrinsics, .step = e.step};
    PublishImage(*latest_);
    ++released;
  }
  return released;
}

void DepthHost::PublishImage(const Frame& frame) {
  // Half a megabyte a frame: converted and written only for a listener (a matched-status read is
  // cheap); a volatile reader would miss what went before it matched anyway.
  if (images_->MatchedSubscribers() <= 0) return;
  ToDepthImage(config_.drone, frame, &image_);
  if (images_->Publish(image_)) ++images_published_;
}

namespace {

constexpr float kMillimetresPerMetre = 1000.0f;
constexpr std::uint32_t kDepthBytesPerPixel = 2;  // 16UC1
// The first count past what a pixel holds, after the rounding's + 0.5: mm + 0.5 < 65536 is
// mm rounding to 65535 (kMaxDepthImageM) or less.
constexpr float kPastMaxDepthMm = static_cast<float>(std::numeric_limits<std::uint16_t>::max()) + 1.0f;

// One depth pixel in millimetres, rounded; 0 for no depth (0, negative, NaN) or beyond
// kMaxDepthImageM (+inf too). Branch-free, in float: a 640x400 frame is 256,000 of these.
inline std::uint16_t DepthMillimetres(float depth_m) {
  const float mm = depth_m * kMillimetresPerMetre + 0.5f;  // round half up (positive only)
  const bool valid = depth_m > 0.0f && mm < kPastMaxDepthMm;  // NaN fails both
  return valid ? static_cast<std::uint16_t>(mm) : std::uint16_t{0};
}

}  // namespace

void ToDepthImage(std::string_view drone, const DepthHost::Frame& frame, bus::CameraImage* out) {
  const cv::Mat& depth_m = frame.frame.depth_m;
  out->drone.assign(drone);
  out->step = frame.step;
  out->sim_time_ns = frame.frame.capture_ns;
  out->width_px = static_cast<std::uint32_t>(depth_m.cols);
  out->height_px = static_cast<std::uint32_t>(depth_m.rows);
  out->row_stride_bytes = kDepthBytesPerPixel * out->width_px;
  out->encoding = "16UC1";
  out->intrinsics = {.fx_px = frame.intrinsics.focal_px,
                     .fy_px = frame.intrinsics.focal_px,
                     .cx_px = frame.intrinsics.cx_px,
                     .cy_px = frame.intrinsics.cy_px,
                     .distortion = {}};
  out->camera_pose = frame.camera_pose;
  out->data.resize(static_cast<std::size_t>(out->height_px) * out->row_stride_bytes);
  std::uint8_t* dst = out->data.data();
  for (int v = 0; v < depth_m.rows; ++v) {
    const float* row = depth_m.ptr<float>(v);
    for (int u = 0; u < depth_m.cols; ++u) {
      const std::uint16_t mm = DepthMillimetres(row[u]);
      *dst++ = static_cast<std::uint8_t>(mm & 0xFFu);  // little-endian, whatever the host's order
      *dst++ = static_cast<std::uint8_t>(mm >> 8);
    }
  }
}

}  // namespace swarmbox::agent
