// The server's stereo pairs (issue #23) with the fake transport: a drone whose airframe has
// stereo enabled gets a pair on StereoTopic at the fixed 5 Hz steps, before its sample, which
// says so; a drone without gets nothing, and no drone pays for it when none has stereo.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "sim_fakes.hpp"
#include "sim_server.hpp"
#include "stereo_capture.hpp"
#include "test_util.hpp"

namespace swarmbox::physics {
namespace {

using testing::FakeClock;
using testing::kMs;
using testing::ScriptedAgents;

TEST(StereoCaptureSchedule, PeriodIsRoundedStepsAndPatchGrowsWithHeight) {
  EXPECT_EQ(StereoCapture::PeriodSteps(5.0, 4 * kMs), 50u);  // 5 Hz at 250 Hz
  EXPECT_EQ(StereoCapture::PeriodSteps(7.0, 4 * kMs), 36u);  // 35.7 rounded
  EXPECT_EQ(StereoCapture::PeriodSteps(1000.0, 4 * kMs), 1u);
  EXPECT_EQ(StereoCapture::PeriodSteps(1e-30, 4 * kMs), 1ULL << 40);  // never, without overflow
  EXPECT_DOUBLE_EQ(StereoCapture::PatchHalfSizeM(0, 1.2566), kPatchMargin_m);
  EXPECT_NEAR(StereoCapture::PatchHalfSizeM(10, 1.2566), 10 * std::tan(0.6283) * 1.5 + 2, 1e-9);
  EXPECT_DOUBLE_EQ(StereoCapture::PatchHalfSizeM(200, 1.2566), kMaxPatchHalfSize_m);
  EXPECT_NE(StereoCapture::NoiseSeed(1, 0, 50), StereoCapture::NoiseSeed(1, 1, 50));
  EXPECT_NE(StereoCapture::NoiseSeed(1, 0, 50), StereoCapture::NoiseSeed(1, 0, 100));
  EXPECT_NE(StereoCapture::NoiseSeed(1, 0, 50), StereoCapture::NoiseSeed(2, 0, 50));
}

// "a" flies x500_depth (stereo 5 Hz, 640 x 400 per camera) 8 m over rubble with a box under it;
// "b" the plain x500. Cameras off: only the pairs are rendered.
class SimServerStereoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    WorldConfig config = testing::CalmWorld();
    config.terrain = Terrain{TerrainKind::kRubble, 0.0};
    config.obstacles.push_back({"box", {1, 1, 0.5}, {2, 2, 1}, 0.3, ObstacleKind::kBox});
    world_ = testing::MakeWorld(config);
    Airframe depth = testing::LoadShippedAirframe("x500_depth");
    Airframe plain = testing::LoadShippedAirframe("x500");
    ASSERT_TRUE(depth.stereo.enabled);
    const double u = depth.HoverRotorSpeed() / depth.motor.max_rot_velocity_rad_s;
    testing::Spawn(*world_, testing::MakeSpawn("a", depth, Vec3{0, 0, 8}, 0, u));
    testing::Spawn(*world_, testing::MakeSpawn("b", plain, Vec3{5, 0, 8}, 0, u));
    agents_.throttle = u;
    agents_.alive = {{"a", true}, {"b", true}};
    out_ = std::tmpfile();
    ASSERT_NE(out_, nullptr);
  }
  void TearDown() override { std::fclose(out_); }

  SimServerOptions Options() {
    SimServerOptions o;
    o.rtf = 0;
    o.cameras = false;
    o.lockstep = {.timeout_ns = 200 * kMs, .join_timeout_ns = 500 * kMs};
    return o;
  }

  std::unique_ptr<World> world_;
  FakeClock clock_;
  ScriptedAgents agents_{clock_};
  std::FILE* out_ = nullptr;
  std::atomic<bool> stop_{false};
};

TEST_F(SimServerStereoTest, PairsGoOutAtTheFixedStepsBeforeTheSampleThatSaysSo) {
  SimServer server(*world_, agents_, clock_, nullptr, Options(), out_);
  for (int k = 0; k < 101; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());
  std::vector<std::string> paired;
  for (std::size_t n = 0; n < agents_.published.size(); ++n) {
    const std::string& line = agents_.published[n];
    if (line.rfind("stereo ", 0) != 0) continue;
    paired.push_back(line);
    ASSERT_LT(n + 1, agents_.published.size());
    EXPECT_EQ(agents_.published[n + 1], "sample " + line.substr(7) + " stereo_frame");
  }
  EXPECT_EQ(paired, (std::vector<std::string>{"stereo a 0", "stereo a 50", "stereo a 100"}));
  EXPECT_EQ(std::count_if(agents_.published.begin(), agents_.published.end(),
                          [](const std::string& l) { return l.find("stereo_frame") != std::string::npos; }),
            3);
  EXPECT_EQ(agents_.pairs.count("b"), 0u);
}

TEST_F(SimServerStereoTest, APairIsBothViewsSideBySideWithTheLeftCamerasPoseAndIntrinsics) {
  SimServer server(*world_, agents_, clock_, nullptr, Options(), out_);
  for (int k = 0; k < 51; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());
  ASSERT_EQ(agents_.pairs["a"].size(), 2u);
  const bus::CameraImage& pair = agents_.pairs["a"][1];
  const StereoSpec& spec = world_->airframe(0).stereo;
  const auto w = static_cast<std::uint32_t>(spec.width_px), h = static_cast<std::uint32_t>(spec.height_px);
  EXPECT_EQ(pair.drone, "a");
  EXPECT_EQ(pair.step, 50u);
  EXPECT_EQ(pair.sim_time_ns, 50 * 4 * kMs);
  EXPECT_EQ(pair.encoding, "mono8");
  EXPECT_EQ(pair.width_px, 2 * w);
  EXPECT_EQ(pair.height_px, h);
  EXPECT_EQ(pair.row_stride_bytes, 2 * w);
  ASSERT_EQ(pair.data.size(), static_cast<std::size_t>(2 * w * h));
  EXPECT_DOUBLE_EQ(pair.intrinsics.fx_px, spec.FocalPx());
  EXPECT_DOUBLE_EQ(pair.intrinsics.fy_px, spec.FocalPx());
  EXPECT_DOUBLE_EQ(pair.intrinsics.cx_px, w / 2.0);
  EXPECT_DOUBLE_EQ(pair.intrinsics.cy_px, h / 2.0);
  // The left camera: baseline / 2 to image left of the pair's centre, under the hovering drone.
  EXPECT_NEAR(pair.camera_pose.position_enu_m[2], 8 + world_->airframe(0).base_height_m + spec.offset_m.z, 0.3);
  EXPECT_NEAR(pair.camera_pose.position_enu_m[1], spec.baseline_m / 2, 0.05);  // optical x = body -y, nose east
  const cv::Mat all(static_cast<int>(h), static_cast<int>(2 * w), CV_8U, const_cast<std::uint8_t*>(pair.data.data()));
  const cv::Mat left = all.colRange(0, static_cast<int>(w)), right = all.colRange(static_cast<int>(w), static_cast<int>(2 * w));
  cv::Scalar mean, std;
  cv::meanStdDev(left, mean, std);
  EXPECT_GT(std[0], 5.0);    // textured rubble, a box and the dots: not a constant image
  EXPECT_NEAR(mean[0], 100, 30);  // auto-exposure's target level
  EXPECT_GT(cv::norm(left, right, cv::NORM_L1), 0.0);  // two views, not one copied
}

TEST_F(SimServerStereoTest, AnUnansweredDronesPairGoesAgainWithItsSample) {
  agents_.alive_from_ns["a"] = 300 * kMs;  // silent for the first 300 ms of the first step
  SimServer server(*world_, agents_, clock_, nullptr, Options(), out_);
  ASSERT_TRUE(server.RunStep(stop_).ok());
  int pairs = 0;
  for (std::size_t n = 0; n < agents_.published.size(); ++n) {
    if (agents_.published[n] != "stereo a 0") continue;
    ++pairs;
    ASSERT_LT(n + 1, agents_.published.size());
    EXPECT_EQ(agents_.published[n + 1], "sample a 0 stereo_frame");
  }
  EXPECT_GT(pairs, 1);
  EXPECT_EQ(agents_.pairs["a"].size(), static_cast<std::size_t>(pairs));
  EXPECT_EQ(agents_.pairs["a"].front().data, agents_.pairs["a"].back().data);  // the same pair again
}

TEST_F(SimServerStereoTest, ALostDroneGetsNoPair) {
  SimServerOptions o = Options();
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  ASSERT_TRUE(server.RunStep(stop_).ok());
  agents_.alive["a"] = false;  // silent from step 1: lost at its timeout
  for (int k = 1; k < 101; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());
  ASSERT_TRUE(world_->Truth(0).lost);
  EXPECT_EQ(agents_.pairs["a"].size(), 1u);  // step 0's only
  // Lost drones still get their samples (to rejoin), without a pair.
  EXPECT_NE(std::find(agents_.published.begin(), agents_.published.end(), "sample a 100"), agents_.published.end());
}

}  // namespace
}  // namespace swarmbox::physics
