// PerceptionHost (agent/app/perception_host.hpp): a rendered frame geolocated with the estimate
// of its capture step, handed over as brain::Detection after the inference latency; frames taken
// tilted, turning or without an estimate of their step are skipped.
#include "perception_host.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "perception_scenes.hpp"
#include "swarmbox/swarm/victim_detector.hpp"

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
  // The shipped detector's own confidence for the person in the frame (the host passes it on).
  double DetectorConfidence() {
    swarm::VictimDetector det;
    std::vector<swarm::ImageBlob> blobs;
    det.Detect(frame_, scene_.intrinsics, scene_.true_pose, 0.0, &blobs);
    return blobs.empty() ? -1.0 : blobs[0].confidence;
  }

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
  // The detector's confidence, passed on (its level for clear people: VictimDetector.*).
  EXPECT_DOUBLE_EQ(out[0].confidence, rig.DetectorConfidence());
  EXPECT_GE(out[0].confidence, 0.5);
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

// A depth frame of the drone's stereo camera over the rig's 20 m: a flat surface `below_m` under
// its left camera (a level body: every pixel's depth along the optical axis is below_m), 640 x 400,
// f = 441 px (the OAK-D Pro's), captured at capture_s.
struct DepthOfASurface {
  depth::DepthFrame frame;
  bus::Pose camera;
  depth::CameraIntrinsics intrinsics{441.0, 320.0, 200.0};
  double surface_z_m = 0;
};
DepthOfASurface FlatDepth(double below_m, double capture_s) {
  DepthOfASurface d;
  d.frame.capture_ns = static_cast<std::int64_t>(capture_s * 1e9);
  d.frame.release_ns = d.frame.capture_ns + 40'000'000;
  d.frame.depth_m = cv::Mat(400, 640, CV_32F, cv::Scalar(below_m));
  d.camera = depth::LeftCameraPose({{0.0, 0.0, 20.0}, {1.0, 0.0, 0.0, 0.0}}, {});
  d.surface_z_m = d.camera.position_enu_m[2] - below_m;
  return d;
}

// Where the detection's ray (from the perception camera through the flat-plane answer) meets z.
Vector3d AlongTheRay(const brain::Detection& flat, double z_m) {
  const airframe::Vec3 offset = PerceptionConfig{}.camera.offset_m;
  const Vector3d cam = swarm::OpticalPoseFromBody(Vector3d(0, 0, 20), Eigen::Quaterniond::Identity(),
                                                  Vector3d(offset.x, offset.y, offset.z)).position_m;
  const Vector3d p(flat.position_m.x, flat.position_m.y, flat.position_m.z);
  return cam + (p - cam) * (cam.z() - z_m) / (cam.z() - p.z());
}

// With a depth frame captured within depth_max_age_s (0.1 s before the camera frame), the person
// is placed where their pixel's ray meets the surface the depth saw (8 m up: a roof or a slab,
// from 12 m: within the depth's 15 m); with one 0.3 s old, or one whose surface lies beyond the
// 15 m (18 m below), the flat-plane answer as without depth, bit for bit.
TEST(PerceptionHost, GeolocatesOnTheSurfaceOfARecentDepthFrame) {
  PerceptionRig flat;
  const std::vector<brain::Detection> without = flat.Run(5.0, 5.1);
  ASSERT_EQ(without.size(), 1u);

  PerceptionRig near;
  const DepthOfASurface surface = FlatDepth(12.0, 4.9);
  near.host().OnDepthFrame(surface.frame, surface.camera, surface.intrinsics);
  const std::vector<brain::Detection> on_surface = near.Run(5.0, 5.1);
  ASSERT_EQ(on_surface.size(), 1u);
  const Vector3d expected = AlongTheRay(without[0], surface.surface_z_m);
  EXPECT_NEAR(on_surface[0].position_m.z, surface.surface_z_m, 1e-4);
  EXPECT_NEAR(on_surface[0].position_m.x, expected.x(), 1e-3);
  EXPECT_NEAR(on_surface[0].position_m.y, expected.y(), 1e-3);
  // 7.95 m of height x tan(off-nadir, 5 m from 20 m) = ~2 m nearer the nadir than the flat answer.
  EXPECT_GT(std::hypot(on_surface[0].position_m.x - without[0].position_m.x,
                       on_surface[0].position_m.y - without[0].position_m.y), 1.5);

  for (const DepthOfASurface& unused : {FlatDepth(12.0, 4.7), FlatDepth(18.0, 4.9)}) {
    PerceptionRig rig;
    rig.host().OnDepthFrame(unused.frame, unused.camera, unused.intrinsics);
    const std::vector<brain::Detection> out = rig.Run(5.0, 5.1);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].position_m.x, without[0].position_m.x);
    EXPECT_EQ(out[0].position_m.y, without[0].position_m.y);
    EXPECT_EQ(out[0].position_m.z, without[0].position_m.z);
    EXPECT_EQ(out[0].sigma_m, without[0].sigma_m);
  }
}

TEST(PerceptionHost, RefusesBadDepthSettings) {
  PerceptionConfig c;
  c.depth_max_age_s = -0.1;
  EXPECT_FALSE(PerceptionHost::Create(c).ok());
  c = PerceptionConfig{};
  c.depth_height_radius_m = 0.0;
  EXPECT_FALSE(PerceptionHost::Create(c).ok());
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
