// DepthHost over the bus (issue #23): a stereo pair published as the physics server does, matched
// by the agent's depth camera, comes out as a depth image on DepthImageTopic at the frame's release
// (the device's 30-50 ms after the exposure), with its size, encoding, stride, intrinsics and the
// depth of the pair's known disparity; with nobody subscribed, no image is made. No physics server:
// the test plays its part on the stereo topic. DDS domains 96-97 (cyclonedds, loopback).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "depth_host.hpp"
#include "swarmbox/bus/participant.hpp"

namespace swarmbox::agent {
namespace {

using namespace std::chrono_literals;

constexpr int kWidthPx = 320;
constexpr int kHeightPx = 200;
constexpr int kDisparityPx = 16;  // every pixel: a fronto-parallel plane
constexpr std::uint64_t kStep = 250;
constexpr std::int64_t kCaptureNs = 1'000'000'000;
constexpr std::int64_t kMs = 1'000'000;
constexpr auto kMatchTimeout = 10s;

airframe::StereoSpec SmallSpec() {
  airframe::StereoSpec spec;
  spec.enabled = true;
  spec.width_px = kWidthPx;
  spec.height_px = kHeightPx;
  spec.latency_min_ms = 30;
  spec.latency_max_ms = 50;
  return spec;
}

// The pair as StereoTopic lays it out: mono8, left | right; the right view is the left one
// shifted by kDisparityPx (a point at column x in the left image is at x - d in the right).
bus::CameraImage PairOfPlane(const airframe::StereoSpec& spec) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> grey(0, 255);
  const int w = spec.width_px;
  std::vector<std::uint8_t> texture(static_cast<std::size_t>((w + kDisparityPx) * spec.height_px));
  for (auto& t : texture) t = static_cast<std::uint8_t>(grey(rng));
  bus::CameraImage pair;
  pair.drone = "d1";
  pair.step = kStep;
  pair.sim_time_ns = kCaptureNs;
  pair.width_px = static_cast<std::uint32_t>(2 * w);
  pair.height_px = static_cast<std::uint32_t>(spec.height_px);
  pair.row_stride_bytes = pair.width_px;
  pair.encoding = "mono8";
  pair.intrinsics = {.fx_px = spec.FocalPx(), .fy_px = spec.FocalPx(), .cx_px = w / 2.0, .cy_px = spec.height_px / 2.0};
  pair.data.resize(static_cast<std::size_t>(pair.height_px) * pair.row_stride_bytes);
  for (int v = 0; v < spec.height_px; ++v) {
    const std::uint8_t* row = &texture[static_cast<std::size_t>(v * (w + kDisparityPx))];
    std::uint8_t* out = &pair.data[static_cast<std::size_t>(v) * pair.row_stride_bytes];
    for (int u = 0; u < w; ++u) {
      out[u] = row[u];                      // left
      out[w + u] = row[u + kDisparityPx];   // right: R(u) = L(u + d)
    }
  }
  return pair;
}

std::uint16_t PixelMm(const bus::CameraImage& image, std::uint32_t u, std::uint32_t v) {
  const std::size_t at = static_cast<std::size_t>(v) * image.row_stride_bytes + 2 * static_cast<std::size_t>(u);
  return static_cast<std::uint16_t>(image.data[at] | (image.data[at + 1] << 8));
}

struct Rig {
  std::unique_ptr<bus::Participant> sim;
  std::unique_ptr<DepthHost> host;
  std::unique_ptr<bus::Publisher<bus::CameraImage>> server;  // the physics server's pair writer
};

Rig MakeRig(int domain) {
  Rig rig;
  auto sim = bus::Participant::Create({.backend = "cyclonedds", .domain_id = domain, .interface = "lo"});
  EXPECT_TRUE(sim) << sim.error().ToString();
  if (!sim) return rig;
  rig.sim = std::move(*sim);
  auto host = DepthHost::Create(*rig.sim, {.drone = "d1", .spec = SmallSpec(), .seed = 3, .pair_timeout = 5000ms});
  EXPECT_TRUE(host) << host.error().ToString();
  if (host) rig.host = std::move(*host);
  auto server = rig.sim->CreatePublisher<bus::CameraImage>(bus::StereoTopic("d1"), bus::Qos::kLockstep);
  EXPECT_TRUE(server) << server.error().ToString();
  if (server) rig.server = std::move(*server);
  return rig;
}

// The server's pair of kStep, then the agent's step a: the pair taken and matched.
void ExposePair(Rig& rig, const bus::Pose& body) {
  ASSERT_TRUE(rig.server->WaitForSubscribers(1, kMatchTimeout));
  ASSERT_TRUE(rig.server->Publish(PairOfPlane(SmallSpec())));
  bus::SensorSample msg;
  msg.step = kStep;
  msg.sim_time_ns = kCaptureNs;
  msg.stereo_frame = true;
  ASSERT_EQ(rig.host->TakePairs(msg, body), FrameWait::kTaken);
  ASSERT_EQ(rig.host->pairs(), 1u);
}

TEST(DepthImageBus, SubscriberGetsTheImageAtTheFramesRelease) {
  Rig rig = MakeRig(96);
  ASSERT_TRUE(rig.host && rig.server);
  auto images = rig.sim->CreateSubscriber<bus::CameraImage>(bus::DepthImageTopic("d1"), bus::Qos::kLockstep);
  ASSERT_TRUE(images) << images.error().ToString();
  auto summaries = rig.sim->CreateSubscriber<bus::DepthSummary>(bus::kDepthTopic, bus::Qos::kState);
  ASSERT_TRUE(summaries) << summaries.error().ToString();
  ASSERT_TRUE((*images)->WaitForPublishers(1, kMatchTimeout));
  bus::Pose body;
  body.position_enu_m = {3.0, 4.0, 2.5};
  ExposePair(rig, body);

  // Within the device's latency nothing leaves; by its longest, the frame and its image have.
  EXPECT_EQ(rig.host->Release(kCaptureNs + 29 * kMs), 0);
  bus::CameraImage image;
  EXPECT_FALSE((*images)->TakeFor(image, 200ms));
  ASSERT_EQ(rig.host->Release(kCaptureNs + 50 * kMs), 1);
  EXPECT_EQ(rig.host->images_published(), 1u);
  ASSERT_TRUE((*images)->TakeFor(image, 5s));
  bus::DepthSummary summary;
  ASSERT_TRUE((*summaries)->TakeFor(summary, 5s));
  EXPECT_EQ(summary.capture_ns, image.sim_time_ns);

  const airframe::StereoSpec spec = SmallSpec();
  EXPECT_EQ(image.drone, "d1");
  EXPECT_EQ(image.step, kStep);
  EXPECT_EQ(image.sim_time_ns, kCaptureNs);
  EXPECT_EQ(image.encoding, "16UC1");
  EXPECT_EQ(image.width_px, static_cast<std::uint32_t>(kWidthPx));
  EXPECT_EQ(image.height_px, static_cast<std::uint32_t>(kHeightPx));
  EXPECT_EQ(image.row_stride_bytes, 2u * kWidthPx);
  EXPECT_EQ(image.data.size(), 2u * kWidthPx * kHeightPx);
  EXPECT_DOUBLE_EQ(image.intrinsics.fx_px, spec.FocalPx());
  EXPECT_DOUBLE_EQ(image.intrinsics.fy_px, spec.FocalPx());
  EXPECT_DOUBLE_EQ(image.intrinsics.cx_px, kWidthPx / 2.0);
  EXPECT_DOUBLE_EQ(image.intrinsics.cy_px, kHeightPx / 2.0);
  EXPECT_EQ(image.camera_pose, rig.host->latest()->camera_pose);  // the left camera, by the estimate
  EXPECT_EQ(image.camera_pose, summary.camera_pose);

  // The plane's depth Z = f b / d in millimetres at the centre; the left band the right view
  // cannot see (columns < num_disparities) has none.
  const double expected_mm = spec.FocalPx() * spec.baseline_m / kDisparityPx * 1000.0;
  EXPECT_NEAR(PixelMm(image, kWidthPx / 2, kHeightPx / 2), expected_mm, 0.01 * expected_mm);
  EXPECT_EQ(PixelMm(image, 0, kHeightPx / 2), 0);
}

TEST(DepthImageBus, NoSubscriberNoImage) {
  Rig rig = MakeRig(97);
  ASSERT_TRUE(rig.host && rig.server);
  auto summaries = rig.sim->CreateSubscriber<bus::DepthSummary>(bus::kDepthTopic, bus::Qos::kState);
  ASSERT_TRUE(summaries) << summaries.error().ToString();
  ExposePair(rig, bus::Pose{});
  ASSERT_EQ(rig.host->Release(kCaptureNs + 50 * kMs), 1);
  EXPECT_EQ(rig.host->images_published(), 0u);  // nothing converted, nothing written
  bus::DepthSummary summary;
  EXPECT_TRUE((*summaries)->TakeFor(summary, 5s));  // the summary goes out as before
  ASSERT_NE(rig.host->latest(), nullptr);           // and the frame stays for the mission
}

}  // namespace
}  // namespace swarmbox::agent
