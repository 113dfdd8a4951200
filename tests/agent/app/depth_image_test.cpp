// ToDepthImage: a released depth frame in bus::DepthImageTopic's form (16UC1 millimetres, 0 = no
// depth), with known depths -> known pixel values, the invalid ones 0, and the left camera's
// intrinsics and pose as the frame's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "depth_host.hpp"

namespace swarmbox::agent {
namespace {

// The 16UC1 pixel (u, v) of `image`, little-endian as the layout says.
std::uint16_t PixelMm(const bus::CameraImage& image, std::uint32_t u, std::uint32_t v) {
  const std::size_t at = static_cast<std::size_t>(v) * image.row_stride_bytes + 2 * static_cast<std::size_t>(u);
  return static_cast<std::uint16_t>(image.data[at] | (image.data[at + 1] << 8));
}

DepthHost::Frame FrameOf(const std::vector<float>& depths_m, int cols) {
  DepthHost::Frame f;
  const int rows = static_cast<int>(depths_m.size()) / cols;
  f.frame.depth_m.create(rows, cols, CV_32F);
  for (int i = 0; i < rows * cols; ++i) f.frame.depth_m.at<float>(i / cols, i % cols) = depths_m[static_cast<std::size_t>(i)];
  f.frame.capture_ns = 1'200'000'000;
  f.frame.release_ns = 1'241'000'000;
  f.step = 300;
  f.intrinsics = {.focal_px = 441.0, .cx_px = 2.0, .cy_px = 1.0};
  f.camera_pose.position_enu_m = {1.0, -2.0, 30.0};
  f.camera_pose.orientation_wxyz = {0.0, 1.0, 0.0, 0.0};
  return f;
}

TEST(DepthImage, KnownDepthsBecomeMillimetresAndInvalidBecomesZero) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  // A disparity of 16 px at the OAK-D Pro's 640x400 (f 441 px, baseline 0.075 m): Z = f b / d.
  const float from_disparity_m = static_cast<float>(441.0 * 0.075 / 16.0);  // 2.0672 m
  const DepthHost::Frame f = FrameOf({1.0f, 2.5f, 0.0f, nan,                         //
                                      -1.0f, 70.0f, inf, 0.0004f,                    //
                                      65.0f, 0.0015f, from_disparity_m, 12.3456f},  //
                                     4);
  bus::CameraImage image;
  ToDepthImage("scout_1", f, &image);
  EXPECT_EQ(image.encoding, "16UC1");
  EXPECT_EQ(image.width_px, 4u);
  EXPECT_EQ(image.height_px, 3u);
  EXPECT_EQ(image.row_stride_bytes, 8u);
  ASSERT_EQ(image.data.size(), 24u);
  EXPECT_EQ(PixelMm(image, 0, 0), 1000);
  EXPECT_EQ(PixelMm(image, 1, 0), 2500);
  EXPECT_EQ(PixelMm(image, 2, 0), 0);     // no depth stays none
  EXPECT_EQ(PixelMm(image, 3, 0), 0);     // NaN
  EXPECT_EQ(PixelMm(image, 0, 1), 0);     // negative
  EXPECT_EQ(PixelMm(image, 1, 1), 0);     // beyond 65.535 m: not representable, so none
  EXPECT_EQ(PixelMm(image, 2, 1), 0);     // +inf
  EXPECT_EQ(PixelMm(image, 3, 1), 0);     // under half a millimetre rounds to none
  EXPECT_EQ(PixelMm(image, 0, 2), 65000);
  EXPECT_EQ(PixelMm(image, 1, 2), 2);     // 1.5 mm rounds half away from zero
  EXPECT_EQ(PixelMm(image, 2, 2), 2067);
  EXPECT_EQ(PixelMm(image, 3, 2), 12346);
  // The deepest a pixel holds, and just past it.
  const DepthHost::Frame edge = FrameOf({65.5354f, 65.5356f}, 2);
  ToDepthImage("scout_1", edge, &image);
  EXPECT_EQ(PixelMm(image, 0, 0), 65535);
  EXPECT_EQ(PixelMm(image, 1, 0), 0);
  ToDepthImage("scout_1", f, &image);
  // Byte order on the wire: 1000 = 0x03E8, low byte first.
  EXPECT_EQ(image.data[0], 0xE8);
  EXPECT_EQ(image.data[1], 0x03);
}

TEST(DepthImage, CarriesTheLeftCamerasIntrinsicsPoseAndExposure) {
  const DepthHost::Frame f = FrameOf({1.0f, 2.0f, 3.0f, 4.0f}, 2);
  bus::CameraImage image;
  ToDepthImage("scout_1", f, &image);
  EXPECT_EQ(image.drone, "scout_1");
  EXPECT_EQ(image.step, 300u);
  EXPECT_EQ(image.sim_time_ns, 1'200'000'000);  // the exposure, as ROS stamps a depth image
  EXPECT_DOUBLE_EQ(image.intrinsics.fx_px, 441.0);
  EXPECT_DOUBLE_EQ(image.intrinsics.fy_px, 441.0);
  EXPECT_DOUBLE_EQ(image.intrinsics.cx_px, 2.0);
  EXPECT_DOUBLE_EQ(image.intrinsics.cy_px, 1.0);
  EXPECT_EQ(image.intrinsics.distortion, (std::array<double, 5>{}));  // rectified
  EXPECT_EQ(image.camera_pose, f.camera_pose);
}

TEST(DepthImage, ReusesTheBufferOfAnEarlierImage) {
  bus::CameraImage image;
  ToDepthImage("scout_1", FrameOf(std::vector<float>(64, 5.0f), 8), &image);
  const std::uint8_t* buffer = image.data.data();
  ToDepthImage("scout_1", FrameOf(std::vector<float>(64, 7.0f), 8), &image);
  EXPECT_EQ(image.data.data(), buffer);  // same size: no new allocation
  EXPECT_EQ(PixelMm(image, 7, 7), 7000);
}

}  // namespace
}  // namespace swarmbox::agent
