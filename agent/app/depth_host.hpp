// DepthHost: the drone's stereo depth camera (OAK-D Pro, the airframe's `stereo:`; issue #23) on
// the agent. The physics server sends the rectified pair of a step on sim/<drone>/stereo (one
// mono8 image, left | right side by side: bus::StereoTopic) before the step's sample, and the
// sample says so (stereo_frame). DepthHost takes the step's pairs, matches them as the device's
// chip would (depth::DepthCamera: StereoSGBM), and releases each depth frame the device's 30-50 ms
// of simulated time after its exposure: its summary goes out on sim/depth (keyed by drone), its
// depth image on sim/<drone>/depth (bus::DepthImageTopic: 16UC1 millimetres, only while someone
// subscribes), and the newest one stays here with its camera's pose for the mission (the lifter's
// drop-spot check, the scouts' clearance, geolocation).
//
//   auto host = DepthHost::Create(*sim, {.drone = "lifter", .spec = af.stereo, .seed = seed});
//   // each step, in the lockstep's order:
//   host->TakePairs(msg, estimate);  // a: the step's pair (waits for it when msg.stereo_frame)
//   host->Release(msg.sim_time_ns);  // c: frames whose latency has passed: published, newest kept
//   if (const DepthHost::Frame* f = host->latest()) ...
//
// Simulated time only decides (the wait for a flagged pair is a wall-clock liveness bound).
#pragma once

#include <chrono>
#include <csignal>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "frame_wait.hpp"
#include "swarmbox/airframe/stereo_spec.hpp"
#include "swarmbox/bus/participant.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/depth/depth_camera.hpp"
#include "swarmbox/depth/ground_plane.hpp"

namespace swarmbox::agent {

struct DepthHostConfig {
  std::string drone;
  airframe::StereoSpec spec;
  std::uint64_t seed = 0;                                    // the device latency's draws
  std::chrono::milliseconds pair_timeout{5000};              // wall clock, a flagged pair
  const volatile std::sig_atomic_t* stop = nullptr;
};

class DepthHost {
 public:
  // A released depth frame with what is needed to put its pixels in the world.
  struct Frame {
    depth::DepthFrame frame;
    bus::Pose camera_pose;                 // the left camera's optical frame at the exposure
    depth::CameraIntrinsics intrinsics;
    std::uint64_t step = 0;                // the exposure's control step (the pair's)
  };

  // Subscribes to the drone's stereo topic and publishes on sim/depth and DepthImageTopic(drone).
  static Result<std::unique_ptr<DepthHost>> Create(bus::Participant& sim, DepthHostConfig config);

  // This step's pairs into the device; with msg.stereo_frame, waits (pair_timeout) for the one of
  // this step. kMissing: the caller logs it; kStopped: stop requested.
  // `body_estimate`: the drone's estimated pose at this step (the pairs' camera pose is derived
  // from it, as the drone would).
  FrameWait TakePairs(const bus::SensorSample& msg, const bus::Pose& body_estimate);
  // The depth frames released by now_ns (simulated): each one's summary published (and its image,
  // when a subscriber is matched), the newest kept. The number released.
  int Release(std::int64_t now_ns);
  // The newest released frame, if any.
  const Frame* latest() const { return latest_ ? &*latest_ : nullptr; }
  std::uint64_t pairs() const { return pairs_; }
  std::uint64_t rejected() const { return rejected_; }  // malformed pairs (size, encoding)
  std::uint64_t images_published() const { return images_published_; }

 private:
  DepthHost(DepthHostConfig config, std::unique_ptr<bus::Subscriber<bus::CameraImage>> pairs,
            std::unique_ptr<bus::Publisher<bus::DepthSummary>> summaries,
            std::unique_ptr<bus::Publisher<bus::CameraImage>> images);
  void OnPair(const bus::CameraImage& image, const bus::Pose& body_estimate);
  void PublishImage(const Frame& frame);

  DepthHostConfig config_;
  std::unique_ptr<bus::Subscriber<bus::CameraImage>> pairs_sub_;
  std::unique_ptr<bus::Publisher<bus::DepthSummary>> summaries_;
  std::unique_ptr<bus::Publisher<bus::CameraImage>> images_;
  bus::CameraImage image_;  // reused: its buffer's capacity stays, one allocation per drone
  depth::DepthCamera camera_;
  FrameBuffers frames_;
  // The pose and intrinsics of each frame in the device, in capture order (the device releases
  // them in that order).
  struct Exposure {
    std::int64_t capture_ns = 0;
    std::uint64_t step = 0;
    bus::Pose camera_pose;
    depth::CameraIntrinsics intrinsics;
  };
  std::deque<Exposure> exposures_;
  std::optional<Frame> latest_;
  std::uint64_t pairs_ = 0;
  std::uint64_t rejected_ = 0;
  std::uint64_t images_published_ = 0;
};

// The largest depth a 16UC1 millimetre pixel holds [m]; deeper pixels are sent as 0 (no depth).
inline constexpr double kMaxDepthImageM = 65.535;

// A released frame in bus::DepthImageTopic's form, into `out` (whose buffer is reused): encoding
// "16UC1", each pixel round(depth_m * 1000) as a little-endian uint16, 0 where depth_m is 0, not
// finite, negative or deeper than kMaxDepthImageM; width and height the frame's, row stride 2 x
// width; fx = fy = the focal length, cx, cy as `frame.intrinsics` (pixel u's centre at u + 0.5),
// distortion 0; camera_pose, step and the exposure's sim_time_ns from the frame.
void ToDepthImage(std::string_view drone, const DepthHost::Frame& frame, bus::CameraImage* out);

}  // namespace swarmbox::agent
