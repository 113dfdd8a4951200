// swarmbox-bench depth_image: what publishing a stereo drone's depth image (bus::DepthImageTopic,
// issue #23) costs its agent per frame, at the OAK-D Pro's 640x400: the 16UC1 conversion
// (ToDepthImage) and the write (Publisher::Publish, cyclonedds on loopback) with one subscriber
// in the same process, whose take is timed apart; and the check a drone nobody listens to pays
// (Publisher::MatchedSubscribers, which is all DepthHost does then). The depth frame is a real
// one: a textured plane 2.07 m away (16 px disparity) matched by depth::DepthCamera.
//   suite=depth_image frames=200 width_px=640 height_px=400 bytes_per_frame=512000 fill=...
//     convert_us=... publish_us=... take_us=... matched_check_us=...
// Thread CPU time per frame, mean over the frames. Figures are printed, never asserted.
// --quick: 20 frames. --frames=N. DDS domain 98.
#include <time.h>

#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "bench.hpp"
#include "depth_host.hpp"
#include "swarmbox/bus/participant.hpp"
#include "swarmbox/depth/depth_camera.hpp"

namespace {

using namespace swarmbox;

constexpr int kDomain = 98;
constexpr int kDisparityPx = 16;

double ThreadCpuUs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e6 + static_cast<double>(ts.tv_nsec) * 1e-3;
}

// A released frame of the spec's size: a random-textured plane kDisparityPx away, matched.
agent::DepthHost::Frame MatchedPlane(const airframe::StereoSpec& spec) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> grey(0, 255);
  cv::Mat wide(spec.height_px, spec.width_px + kDisparityPx, CV_8UC1);
  for (int v = 0; v < wide.rows; ++v) {
    for (int u = 0; u < wide.cols; ++u) wide.at<std::uint8_t>(v, u) = static_cast<std::uint8_t>(grey(rng));
  }
  const cv::Mat left = wide.colRange(0, spec.width_px).clone();
  const cv::Mat right = wide.colRange(kDisparityPx, spec.width_px + kDisparityPx).clone();
  depth::DepthCamera camera({.match = {.num_disparities = spec.num_disparities}, .latency_min_ms = 30,
                             .latency_max_ms = 30},
                            1);
  camera.OnPair(0, left, right, spec.FocalPx(), spec.baseline_m);
  agent::DepthHost::Frame f;
  f.frame = *camera.Poll(1'000'000'000);
  f.intrinsics = {.focal_px = spec.FocalPx(), .cx_px = spec.width_px / 2.0, .cy_px = spec.height_px / 2.0};
  return f;
}

int Fail(const std::string& what) {
  std::fprintf(stderr, "depth_image bench: %s\n", what.c_str());
  return 2;
}

int RunDepthImageBench(const bench::Args& args) {
  const long frames = args.GetInt("frames", args.quick ? 20 : 200);
  airframe::StereoSpec spec;  // the OAK-D Pro's defaults: 640x400
  spec.enabled = true;
  const agent::DepthHost::Frame frame = MatchedPlane(spec);
  auto sim = bus::Participant::Create({.backend = "cyclonedds", .domain_id = kDomain, .interface = "lo"});
  if (!sim) return Fail(sim.error().ToString());
  auto pub = (*sim)->CreatePublisher<bus::CameraImage>(bus::DepthImageTopic("d1"), bus::Qos::kLockstep);
  if (!pub) return Fail(pub.error().ToString());
  // The drone nobody listens to: the matched-status read only.
  double check_us = 0;
  int matched = 0;
  for (long i = 0; i < frames; ++i) {
    const double t0 = ThreadCpuUs();
    matched += (*pub)->MatchedSubscribers();
    check_us += ThreadCpuUs() - t0;
  }
  auto sub = (*sim)->CreateSubscriber<bus::CameraImage>(bus::DepthImageTopic("d1"), bus::Qos::kLockstep);
  if (!sub || !(*pub)->WaitForSubscribers(1, std::chrono::seconds(10))) {
    return Fail("no subscriber matched");
  }
  bus::CameraImage image, received;
  double convert_us = 0, publish_us = 0, take_us = 0;
  long taken = 0;
  for (long i = 0; i < frames; ++i) {
    const double t0 = ThreadCpuUs();
    agent::ToDepthImage("d1", frame, &image);
    const double t1 = ThreadCpuUs();
    if (auto s = (*pub)->Publish(image); !s) return Fail(s.error().ToString());
    const double t2 = ThreadCpuUs();
    taken += (*sub)->TakeFor(received, std::chrono::seconds(1)) ? 1 : 0;
    convert_us += t1 - t0;
    publish_us += t2 - t1;
    take_us += ThreadCpuUs() - t2;
  }
  const double fill = static_cast<double>(cv::countNonZero(frame.frame.depth_m)) / static_cast<double>(frame.frame.depth_m.total());
  const double n = static_cast<double>(frames);
  std::printf(
      "suite=depth_image frames=%ld width_px=%d height_px=%d bytes_per_frame=%zu fill=%.2f convert_us=%.0f "
      "publish_us=%.0f take_us=%.0f taken=%ld matched_check_us=%.2f matched_before=%d\n",
      frames, spec.width_px, spec.height_px, image.data.size(), fill, convert_us / n, publish_us / n, take_us / n,
      taken, check_us / n, matched);
  return taken == frames ? 0 : 1;
}

}  // namespace

SWARMBOX_BENCH_SUITE(depth_image,
                     "a stereo drone's depth image on the bus: bytes and agent CPU per 640x400 frame (16UC1 "
                     "conversion, publish, a subscriber's take) and the matched check without a subscriber",
                     RunDepthImageBench);
