// Perception building blocks on synthetic inputs: geolocation (pinhole ray casting), the latency
// queue, and the detector on images drawn with OpenCV.
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "swarmbox/swarm/geolocation.hpp"
#include "swarmbox/swarm/latency_queue.hpp"
#include "swarmbox/swarm/victim_detector.hpp"
#include "swarmbox/swarm/victim_perception.hpp"

namespace swarmbox::swarm {
namespace {

using Eigen::Quaterniond;
using Eigen::Vector2d;
using Eigen::Vector3d;

const PinholeIntrinsics kK{160.0 / std::tan(0.6), 160.0 / std::tan(0.6), 160.0, 120.0};

Quaterniond Yaw(double yaw_rad) { return Quaterniond(Eigen::AngleAxisd(yaw_rad, Vector3d::UnitZ())); }

// Camera conventions (camera_image.hpp): looking down, image up = body +x, image right = body -y.
TEST(Geolocation, NadirCameraSeesForwardUpAndLeftLeft) {
  const OpticalPose cam = OpticalPoseFromBody(Vector3d(10, 20, 30), Yaw(0.0), Vector3d::Zero());
  const auto centre = PixelToGround({kK.cx_px, kK.cy_px}, kK, cam, 0.0);
  ASSERT_TRUE(centre.has_value());
  EXPECT_NEAR((*centre - Vector3d(10, 20, 0)).norm(), 0.0, 1e-9);
  // Nose east: a point 5 m east is above the centre (v < cy), 5 m north (body left) is left.
  const auto east = ProjectToPixel(Vector3d(15, 20, 0), kK, cam);
  const auto north = ProjectToPixel(Vector3d(10, 25, 0), kK, cam);
  ASSERT_TRUE(east && north);
  EXPECT_NEAR(east->x(), kK.cx_px, 1e-9);
  EXPECT_NEAR(east->y(), kK.cy_px - kK.fy_px * 5.0 / 30.0, 1e-9);
  EXPECT_NEAR(north->x(), kK.cx_px - kK.fx_px * 5.0 / 30.0, 1e-9);
}

TEST(Geolocation, RayCastingInvertsProjectionForTiltedPoses) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 200; ++i) {
    const Quaterniond att = Yaw(3 * u(rng)) * Quaterniond(Eigen::AngleAxisd(0.3 * u(rng), Vector3d::UnitX())) *
                            Quaterniond(Eigen::AngleAxisd(0.3 * u(rng), Vector3d::UnitY()));
    const OpticalPose cam = OpticalPoseFromBody(Vector3d(5 * u(rng), 5 * u(rng), 20 + 10 * u(rng)), att,
                                                Vector3d(0.5, 0, -0.3));
    const Vector2d px(160 + 150 * u(rng), 120 + 110 * u(rng));
    const auto g = PixelToGround(px, kK, cam, 0.0);
    ASSERT_TRUE(g.has_value());
    EXPECT_NEAR(g->z(), 0.0, 1e-9);
    const auto back = ProjectToPixel(*g, kK, cam);
    ASSERT_TRUE(back.has_value());
    EXPECT_NEAR((*back - px).norm(), 0.0, 1e-6);  // [px]
  }
}

TEST(Geolocation, RaysAboveTheHorizonHaveNoGroundPoint) {
  // Pitched 100 degrees: the camera looks up past the horizon.
  const Quaterniond att(Eigen::AngleAxisd(100.0 * std::numbers::pi / 180, Vector3d::UnitY()));
  const OpticalPose cam = OpticalPoseFromBody(Vector3d(0, 0, 10), att, Vector3d::Zero());
  EXPECT_FALSE(PixelToGround({kK.cx_px, kK.cy_px}, kK, cam, 0.0).has_value());
  // And below the ground plane.
  const OpticalPose under = OpticalPoseFromBody(Vector3d(0, 0, -1), Quaterniond::Identity(), Vector3d::Zero());
  EXPECT_FALSE(PixelToGround({kK.cx_px, kK.cy_px}, kK, under, 0.0).has_value());
}

TEST(Geolocation, GroundSigmaAddsErrorsInQuadrature) {
  EXPECT_NEAR(GroundSigma(30.0, 0.3, 0.01, 0.0, 233.0), std::sqrt(0.09 + 0.09), 1e-12);
  EXPECT_GT(GroundSigma(40.0, 0.3, 0.01, 1.0, 233.0), GroundSigma(20.0, 0.3, 0.01, 1.0, 233.0));
}

TEST(LatencyQueue, DetectionsBecomeVisibleAtCapturePlusLatency) {
  LatencyQueue q(0.040, 8);
  GroundDetection d;
  d.confidence = 0.9;
  q.Push(d, 10.0);
  q.Push(d, 10.2);
  std::vector<GroundDetection> out;
  q.PopVisible(10.039, &out);
  EXPECT_TRUE(out.empty());
  q.PopVisible(10.040, &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_DOUBLE_EQ(out[0].capture_time_s, 10.0);
  EXPECT_DOUBLE_EQ(out[0].visible_time_s, 10.040);
  q.PopVisible(11.0, &out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_DOUBLE_EQ(out[1].capture_time_s, 10.2);
  EXPECT_EQ(q.pending(), 0u);
}

TEST(LatencyQueue, KeepsVisibleTimeOrderAndDropsTheOldestWhenFull) {
  LatencyQueue q(0.1, 3);
  GroundDetection d;
  for (double t : {1.0, 3.0, 2.0}) q.Push(d, t);  // out-of-order frame
  q.Push(d, 4.0);                                  // full: drops t = 1.0
  EXPECT_EQ(q.dropped(), 1u);
  std::vector<GroundDetection> out;
  q.PopVisible(100.0, &out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_DOUBLE_EQ(out[0].capture_time_s, 2.0);
  EXPECT_DOUBLE_EQ(out[1].capture_time_s, 3.0);
  EXPECT_DOUBLE_EQ(out[2].capture_time_s, 4.0);
}

// A synthetic frame: grass-like noise, an optional person figure drawn at `centre_px` with the
// renderer's colours at `px_per_m`, optional clutter.
cv::Mat Frame(std::uint64_t seed) {
  cv::Mat img(240, 320, CV_8UC3);
  cv::RNG rng(seed);
  rng.fill(img, cv::RNG::UNIFORM, cv::Scalar(30, 80, 40), cv::Scalar(80, 150, 120));
  return img;
}
void DrawPerson(cv::Mat& img, cv::Point2d centre_px, double px_per_m, double heading_deg) {
  const double a = heading_deg * std::numbers::pi / 180;
  const cv::Point2d h(std::cos(a), -std::sin(a));
  const cv::Point2d body = centre_px - 0.15 * px_per_m * h;
  const cv::Point2d head = centre_px + 0.70 * px_per_m * h;
  cv::ellipse(img, cv::RotatedRect(body, cv::Size2f(static_cast<float>(1.44 * px_per_m), static_cast<float>(0.48 * px_per_m)), static_cast<float>(-heading_deg)),
              cv::Scalar(0, 120, 255), cv::FILLED);
  cv::ellipse(img, cv::RotatedRect(head, cv::Size2f(static_cast<float>(0.26 * px_per_m), static_cast<float>(0.22 * px_per_m)), static_cast<float>(-heading_deg)),
              cv::Scalar(40, 210, 255), cv::FILLED);
}
void AddNoise(cv::Mat& img, double std, std::uint64_t seed) {
  cv::Mat n(img.size(), CV_16SC3);
  cv::RNG rng(seed);
  rng.fill(n, cv::RNG::NORMAL, 0.0, std);
  cv::add(img, n, img, cv::noArray(), CV_8UC3);
}

TEST(VictimDetector, FindsAPersonAtItsCentroidWithHighConfidence) {
  VictimDetector det;
  std::vector<ImageBlob> blobs;
  for (double ppm : {233.0 / 10, 233.0 / 25, 233.0 / 40}) {  // 10, 25 and 40 m altitude
    cv::Mat img = Frame(1);
    DrawPerson(img, {150, 110}, ppm, 30.0);
    AddNoise(img, 6.0, 2);
    det.Detect(img, ppm, &blobs);
    ASSERT_EQ(blobs.size(), 1u) << "px/m " << ppm;
    // The area-weighted centre of the figure is ~0.085 m toward the feet of `centre`.
    EXPECT_LT((blobs[0].centroid_px - Vector2d(150, 110)).norm(), 0.15 * ppm + 1.0) << "px/m " << ppm;
    EXPECT_GE(blobs[0].confidence, 0.9) << "px/m " << ppm;
    EXPECT_FALSE(blobs[0].partial);
  }
}

TEST(VictimDetector, RejectsBlobsOfTheWrongSizeAndNoise) {
  VictimDetector det;
  std::vector<ImageBlob> blobs;
  const double ppm = 233.0 / 20;
  cv::Mat img = Frame(3);
  cv::rectangle(img, cv::Rect(20, 20, 80, 60), cv::Scalar(0, 120, 255), cv::FILLED);   // a tarp: too big
  cv::circle(img, cv::Point(250, 200), 1, cv::Scalar(0, 120, 255), cv::FILLED);        // a speck
  cv::rectangle(img, cv::Rect(200, 40, 30, 30), cv::Scalar(160, 155, 150), cv::FILLED);  // grey roof
  AddNoise(img, 8.0, 4);
  det.Detect(img, ppm, &blobs);
  EXPECT_TRUE(blobs.empty());
  cv::Mat plain = Frame(5);
  AddNoise(plain, 12.0, 6);
  det.Detect(plain, ppm, &blobs);
  EXPECT_TRUE(blobs.empty());
}

TEST(VictimDetector, APersonCutByTheBorderIsAPartialViewBelowTheConfirmationThreshold) {
  VictimDetector det;
  std::vector<ImageBlob> blobs;
  const double ppm = 233.0 / 15;
  cv::Mat img = Frame(7);
  DrawPerson(img, {3, 120}, ppm, 0.0);  // half of it beyond the left edge
  det.Detect(img, ppm, &blobs);
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_TRUE(blobs[0].partial);
  EXPECT_LE(blobs[0].confidence, 0.8);
  EXPECT_LT(blobs[0].confidence, 0.9);  // MissionState::kHighConfidence: cannot confirm alone
}

// The whole pipeline on a synthetic frame: the detection appears only after the latency, on the
// ground where the person was drawn.
TEST(VictimPerception, GeolocatesAndDelaysByTheInferenceLatency) {
  const OpticalPose cam = OpticalPoseFromBody(Vector3d(0, 0, 20), Yaw(0.0), Vector3d::Zero());
  const Vector3d person(4.0, -3.0, 0.0);
  const auto px = ProjectToPixel(person, kK, cam);
  ASSERT_TRUE(px.has_value());
  cv::Mat img = Frame(9);
  DrawPerson(img, {px->x(), px->y()}, kK.fx_px / 20.0, 90.0);
  PerceptionParams params;
  params.latency_s = 0.040;
  VictimPerception perception(params);
  EXPECT_EQ(perception.ProcessFrame(img, kK, cam, 5.0), 1);
  std::vector<GroundDetection> out;
  perception.PopVisible(5.039, &out);
  EXPECT_TRUE(out.empty());
  perception.PopVisible(5.040, &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_LT((out[0].position_m - person).norm(), 0.3);  // [m]
  EXPECT_DOUBLE_EQ(out[0].capture_time_s, 5.0);
  EXPECT_GT(out[0].sigma_m, 0.0);
  EXPECT_GE(out[0].confidence, 0.9);
}

}  // namespace
}  // namespace swarmbox::swarm
