// PerceptionHost (agent/app/perception_host.hpp): a synthetic frame geolocated with the estimate
// of its capture step, handed over as brain::Detection after the inference latency; frames taken
// tilted, turning or without an estimate of their step are skipped.
#include "perception_host.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace swarmbox::agent {
namespace {

using Eigen::Vector3d;

const swarm::PinholeIntrinsics kK{160.0 / std::tan(0.6), 160.0 / std::tan(0.6), 160.0, 120.0};

// Grass, and a person in orange lying at `centre_px` (as the detector's own tests draw one).
cv::Mat FrameWithPerson(cv::Point2d centre_px, double px_per_m) {
  cv::Mat img(240, 320, CV_8UC3);
  cv::RNG rng(9);
  rng.fill(img, cv::RNG::UNIFORM, cv::Scalar(30, 80, 40), cv::Scalar(80, 150, 120));
  const cv::Point2d body = centre_px - 0.15 * px_per_m * cv::Point2d(0, -1);
  const cv::Point2d head = centre_px + 0.70 * px_per_m * cv::Point2d(0, -1);
  cv::ellipse(img, cv::RotatedRect(body, cv::Size2f(static_cast<float>(1.44 * px_per_m), static_cast<float>(0.48 * px_per_m)), -90.0f),
              cv::Scalar(0, 120, 255), cv::FILLED);
  cv::ellipse(img, cv::RotatedRect(head, cv::Size2f(static_cast<float>(0.26 * px_per_m), static_cast<float>(0.22 * px_per_m)), -90.0f),
              cv::Scalar(40, 210, 255), cv::FILLED);
  return img;
}

class PerceptionRig {
 public:
  PerceptionRig() {
    PerceptionConfig c;
    c.inference_latency_s = 0.040;
    host_ = std::move(*PerceptionHost::Create(c));
    est_.valid = true;
    est_.pos_m = Vector3d(0, 0, 20);
    const auto px = swarm::ProjectToPixel(person_, kK, swarm::OpticalPoseFromBody(est_.pos_m, est_.att, Vector3d::Zero()));
    frame_ = FrameWithPerson({px->x(), px->y()}, kK.fx_px / 20.0);
  }
  // Estimates every 4 ms up to `t_s`; a frame captured at `capture_s`; what is visible at `t_s`.
  std::vector<brain::Detection> Run(double capture_s, double t_s) {
    for (; t_ < t_s - 1e-9; t_ += 0.004) host_->RecordEstimate(t_, est_);
    host_->OnCameraFrame(frame_, kK, capture_s);
    std::vector<brain::Detection> out;
    host_->PopVisible(t_s, &out);
    return out;
  }
  flight::StateEstimate& estimate() { return est_; }
  PerceptionHost& host() { return *host_; }
  const Vector3d& person() const { return person_; }

 private:
  std::unique_ptr<PerceptionHost> host_;
  flight::StateEstimate est_;
  Vector3d person_{4.0, -3.0, 0.0};
  cv::Mat frame_;
  double t_ = 0.0;
};

TEST(PerceptionHost, GeolocatesWithTheCaptureEstimateAndHandsItOverAfterTheLatency) {
  PerceptionRig rig;
  EXPECT_TRUE(rig.Run(5.0, 5.0).empty());  // captured now: still in inference
  std::vector<brain::Detection> out;
  rig.host().PopVisible(5.039, &out);
  EXPECT_TRUE(out.empty());
  rig.host().PopVisible(5.040, &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].label, "victim");
  EXPECT_NEAR(static_cast<double>(out[0].t_ns) * 1e-9, 5.0, 1e-9);
  EXPECT_LT(std::hypot(out[0].position_m.x - rig.person().x(), out[0].position_m.y - rig.person().y()), 0.3);
  EXPECT_GT(out[0].sigma_m, 0.0);
  EXPECT_GE(out[0].confidence, 0.9);
  out.clear();
  rig.host().PopVisible(6.0, &out);
  EXPECT_TRUE(out.empty());  // once
}

TEST(PerceptionHost, SkipsTiltedTurningAndUnknownCaptureSteps) {
  {
    PerceptionRig rig;
    rig.estimate().att = flight::Quat(Eigen::AngleAxisd(0.3, Vector3d::UnitX()));  // 0.3 rad > 0.2 rad
    EXPECT_TRUE(rig.Run(5.0, 5.1).empty());
  }
  {
    PerceptionRig rig;
    rig.estimate().rate_radps = Vector3d(0, 0, 0.8);  // turning at 0.8 rad/s > 0.5 rad/s
    EXPECT_TRUE(rig.Run(5.0, 5.1).empty());
  }
  {
    PerceptionRig rig;
    EXPECT_TRUE(rig.Run(4.0, 5.1).empty());  // older than the 0.5 s of estimates kept
  }
  {
    PerceptionRig rig;
    EXPECT_EQ(rig.Run(5.0, 5.1).size(), 1u);  // the same frame, steady: seen
  }
}

TEST(PerceptionHost, RefusesANegativeLatency) {
  PerceptionConfig c;
  c.inference_latency_s = -0.01;
  auto r = PerceptionHost::Create(c);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().ToString().find("latency"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::agent
