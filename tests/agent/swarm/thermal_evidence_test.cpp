// Thermal evidence (agent/swarm thermal_evidence.hpp): the contrast at a ground point, the fitted
// log-likelihood ratio, and VictimPerception taking it into the colour detector's confidence.
#include "swarmbox/swarm/thermal_evidence.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "perception_score.hpp"
#include "swarmbox/swarm/geolocation.hpp"
#include "swarmbox/swarm/victim_detector.hpp"
#include "swarmbox/swarm/victim_perception.hpp"

namespace swarmbox::swarm {
namespace {

using Eigen::Quaterniond;
using Eigen::Vector2d;
using Eigen::Vector3d;

// A level thermal camera (320 x 256, the Boson's 358.3 px focal length) `altitude_m` over (x, y),
// seeing ground at `ground_k` with a disc `warm_k` warmer, `radius_m` across, at `warm_at`.
ThermalView FlatView(const Vector3d& camera_m, double ground_k, const Vector3d& warm_at, double warm_k,
                     double radius_m) {
  ThermalView v;
  v.k = {358.3, 358.3, 160.0, 128.0};
  v.pose = OpticalPoseFromBody(camera_m, Quaterniond::Identity(), Vector3d::Zero());
  v.kelvin = cv::Mat(256, 320, CV_32F, cv::Scalar(ground_k));
  if (warm_k != 0) {
    const std::optional<Vector2d> px = ProjectToPixel(warm_at, v.k, v.pose);
    if (px) {
      const double r_px = radius_m * v.k.fx_px / (warm_at - camera_m).norm();
      cv::circle(v.kelvin, cv::Point(static_cast<int>(px->x()), static_cast<int>(px->y())),
                 static_cast<int>(std::lround(r_px)), cv::Scalar(ground_k + warm_k), cv::FILLED);
    }
  }
  return v;
}

TEST(ThermalEvidence, TheContrastIsTheWarmSpotOverTheGroundAroundIt) {
  const Vector3d person(2.0, 1.0, 0.0);
  const ThermalView v = FlatView({0, 0, 20}, 290.0, person, 8.0, 0.4);
  const std::optional<double> c = ThermalContrastAt(v, person, 0.7);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(*c, 8.0, 1e-3);
  // 3 m away there is only ground.
  const std::optional<double> beside = ThermalContrastAt(v, person + Vector3d(0, 3.0, 0), 0.7);
  ASSERT_TRUE(beside.has_value());
  EXPECT_NEAR(*beside, 0.0, 1e-3);
  // A point whose ring leaves the frame (the footprint is 17.9 x 14.3 m from 20 m) has none.
  EXPECT_FALSE(ThermalContrastAt(v, Vector3d(8.5, 0, 0), 0.7).has_value());
  EXPECT_FALSE(ThermalContrastAt(v, person, 0.0).has_value());
}

TEST(ThermalEvidence, TheRatioIsLinearInTheContrastAndClamped) {
  const ThermalEvidence e{0.5, 4.0, 0.7};
  EXPECT_DOUBLE_EQ(e.Llr(4.0), 0.0);
  EXPECT_DOUBLE_EQ(e.Llr(10.0), 3.0);
  EXPECT_DOUBLE_EQ(e.Llr(-1.0), -2.5);
  EXPECT_DOUBLE_EQ(e.Llr(1000.0), e.Llr(kMaxContrastK));
  EXPECT_DOUBLE_EQ(e.Llr(-1000.0), e.Llr(kMinContrastK));
}

// The shipped fit (models/thermal_evidence.yaml): warmer is more likely a person, and a few kelvin
// of contrast (a sun-warmed backpack's, the ground's ring) say little either way.
TEST(ThermalEvidence, TheShippedFitSaysWarmerIsMoreLikelyAPerson) {
  const ThermalEvidence& e = ShippedThermalEvidence();
  EXPECT_GT(e.slope_per_k, 0.05);
  EXPECT_GT(e.offset_k, 0.0);
  EXPECT_LT(e.offset_k, 15.0);
  EXPECT_GT(e.radius_m, 0.3);
  EXPECT_LT(e.Llr(0.0), 0.0);
  EXPECT_GT(e.Llr(15.0), 0.0);
}

TEST(ThermalEvidence, AFitWithoutItsFiguresIsRefused) {
  auto parse = [](const char* text) {
    auto root = yaml::Parse(text, "thermal_evidence.yaml");
    EXPECT_TRUE(root.ok());
    return ParseThermalEvidence(*root);
  };
  EXPECT_TRUE(
      parse("thermal_evidence: {slope_per_k: 0.3, offset_k: 5, radius_m: 0.7, fit: {seed: 1}}\n").ok());
  EXPECT_FALSE(parse("thermal_evidence: {slope_per_k: 0.3, offset_k: 5}\n").ok());
  EXPECT_FALSE(parse("thermal_evidence: {slope_per_k: -0.3, offset_k: 5, radius_m: 0.7}\n").ok());
  EXPECT_FALSE(parse("thermal_evidence: {slope_per_k: 0.3, offset_k: 5, radius_m: 0.7, colour: red}\n").ok());
  EXPECT_FALSE(parse("other: 1\n").ok());
}

// A rendered colour frame with one person, and thermal frames taken with it: warm where the
// person lies raises the detector's confidence, a flat field lowers it, and a frame that does not
// see the point leaves it as the colour detector gave it.
TEST(VictimPerception, AThermalFrameMovesTheColourDetectorsConfidence) {
  const Vector3d person(4.0, -3.0, 0.0);
  physics::WorldConfig w;
  w.name = "unit";
  w.ground_texture_seed = 11;
  physics::Victim v;
  v.id = "v1";
  v.x_m = person.x();
  v.y_m = person.y();
  v.heading_rad = std::numbers::pi / 2;
  w.victims.push_back(v);
  Result<testing::Scene> s = perception_scenes::RenderView(w, {0.0, 0.0}, 20.0, 0.0, 4.0);
  ASSERT_TRUE(s.ok()) << s.error().ToString();
  cv::Mat bgr(s->image.height_px, s->image.width_px, CV_8UC3, s->image.bgr.data());
  PerceptionParams params;
  params.thermal = ThermalEvidence{0.35, 5.5, 0.7};
  const Vector3d camera = s->true_pose.position_m;

  VictimPerception colour(params), warm(params), flat(params), elsewhere(params);
  ASSERT_EQ(colour.ProcessFrame(bgr, s->intrinsics, s->true_pose, 5.0), 1);
  const ThermalView warm_view = FlatView(camera, 290.0, person, 10.0, 0.4);
  ASSERT_EQ(warm.ProcessFrame(bgr, s->intrinsics, s->true_pose, 5.0, nullptr, &warm_view), 1);
  const ThermalView flat_view = FlatView(camera, 290.0, person, 0.0, 0.4);
  // A thermal camera 30 m off: the person is outside its frame.
  const ThermalView away = FlatView(camera + Vector3d(30.0, 0, 0), 290.0, person, 0.0, 0.4);
  ASSERT_EQ(elsewhere.ProcessFrame(bgr, s->intrinsics, s->true_pose, 5.0, nullptr, &away), 1);
  std::vector<GroundDetection> a, b, c;
  colour.PopVisible(10.0, &a);
  warm.PopVisible(10.0, &b);
  elsewhere.PopVisible(10.0, &c);
  ASSERT_TRUE(a.size() == 1u && b.size() == 1u && c.size() == 1u);
  const double rgb = a[0].confidence;
  const std::optional<double> contrast = ThermalContrastAt(warm_view, b[0].position_m, 0.7);
  ASSERT_TRUE(contrast.has_value());
  const double logit = std::log(rgb / (1 - rgb)) + params.thermal.Llr(*contrast);
  EXPECT_NEAR(b[0].confidence, 1.0 / (1.0 + std::exp(-logit)), 1e-9);
  EXPECT_GT(b[0].confidence, rgb);
  EXPECT_DOUBLE_EQ(c[0].confidence, rgb);
  // Flat: no contrast, Llr(0) = -1.9: the confidence falls by that much in logit.
  ASSERT_EQ(flat.ProcessFrame(bgr, s->intrinsics, s->true_pose, 5.0, nullptr, &flat_view), 1);
  std::vector<GroundDetection> d;
  flat.PopVisible(10.0, &d);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_LT(d[0].confidence, rgb);
  EXPECT_NEAR(std::log(d[0].confidence / (1 - d[0].confidence)),
              std::log(rgb / (1 - rgb)) + params.thermal.Llr(0.0), 1e-6);
}

}  // namespace
}  // namespace swarmbox::swarm
