// PerceptionHost (agent/app/perception_host.hpp): a rendered frame geolocated with the estimate
// of its capture step, handed over as brain::Detection after the inference latency; frames taken
// tilted, turning or without an estimate of their step are skipped.
#include "perception_host.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "perception_scenes.hpp"

namespace swarmbox::agent {
namespace {

using Eigen::Vector3d;

// A frame of the physics renderer (the detector is trained on its frames): a person lying
// north-south at `person` seen from 20 m over the origin, camera yaw 0.
perception_scenes::Scene RenderedFrame(const Vector3d& person) {
  physics::WorldConfig w;
  w.name = "host";
  w.ground_texture_seed = 9;
  physics::Victim v;
  v.id = "v1";
  v.x_m = person.x();
  v.y_m = person.y();
  v.heading_rad = M_PI / 2;
  w.victims.push_back(v);
  Result<perception_scenes::Scene> s = perception_scenes::RenderView(w, {0.0, 0.0}, 20.0, 0.0, 4.0);
  SWARMBOX_CHECK(s.ok());
  return std::move(*s);
}

class PerceptionRig {
 public:
  PerceptionRig() {
    PerceptionConfig c;
    c.inference_latency_s = 0.040;
    host_ = std::move(*PerceptionHost::Create(c));
    est_.valid = true;
    est_.pos_m = Vector3d(0, 0, 20);
    scene_ = RenderedFrame(person_);
    frame_ = cv::Mat(scene_.image.height_px, scene_.image.width_px, CV_8UC3, scene_.image.bgr.data());
  }
  // Estimates every 4 ms up to `t_s`; a frame captured at `capture_s`; what is visible at `t_s`.
  std::vector<brain::Detection> Run(double capture_s, double t_s) {
    for (; t_ < t_s - 1e-9; t_ += 0.004) host_->RecordEstimate(t_, est_);
    host_->OnCameraFrame(frame_, scene_.intrinsics, capture_s);
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
  perception_scenes::Scene scene_;
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
    rig.estimate().rate_rad_s = Vector3d(0, 0, 0.8);  // turning at 0.8 rad/s > 0.5 rad/s
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
