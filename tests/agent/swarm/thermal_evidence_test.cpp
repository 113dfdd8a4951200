// Thermal evidence (agent/swarm thermal_evidence.hpp): the contrast at a ground point, the thermal
// patch and its classifier, the fitted log-likelihood ratio, and VictimPerception taking it into
// the colour detector's confidence.
#include "swarmbox/swarm/thermal_evidence.hpp"

#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "perception_score.hpp"
#include "swarmbox/airframe/thermal_spec.hpp"
#include "swarmbox/physics/thermal_renderer.hpp"
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

// A fusion of the colour logit and the contrast alone (radius 0.7 m, no classifier).
ThermalEvidence Evidence(double colour_weight, double slope_per_k, double bias) {
  ThermalEvidence e;
  e.colour_weight = colour_weight;
  e.slope_per_k = slope_per_k;
  e.bias = bias;
  e.radius_m = 0.7;
  return e;
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

TEST(ThermalEvidence, ThePatchIsTheGroundAroundThePointOverItsMedianInTensOfKelvin) {
  const Vector3d person(2.0, 1.0, 0.0);
  const ThermalView v = FlatView({0, 0, 20}, 290.0, person, 8.0, 0.4);
  cv::Mat patch;
  ASSERT_TRUE(ThermalPatchAt(v, person, &patch));
  ASSERT_EQ(patch.type(), CV_32F);
  ASSERT_EQ(patch.rows, kThermalPatchPx);
  ASSERT_EQ(patch.cols, kThermalPatchPx);
  const int mid = kThermalPatchPx / 2;
  EXPECT_NEAR(patch.at<float>(mid, mid), 0.8F, 1e-3);  // 8 K over the ground
  EXPECT_NEAR(patch.at<float>(0, 0), 0.0F, 1e-6);      // the ground: the median
  // Ground is east right and north up: a warm spot 0.8 m east of the point is right of centre.
  cv::Mat east;
  ASSERT_TRUE(ThermalPatchAt(v, person - Vector3d(0.8, 0, 0), &east));
  EXPECT_NEAR(east.at<float>(mid, mid + 10), 0.8F, 1e-3);
  EXPECT_NEAR(east.at<float>(mid, mid - 10), 0.0F, 1e-6);
  // Far warmer than kThermalPatchMax x 10 K: clamped.
  const ThermalView hot = FlatView({0, 0, 20}, 290.0, person, 80.0, 0.4);
  ASSERT_TRUE(ThermalPatchAt(hot, person, &patch));
  EXPECT_FLOAT_EQ(patch.at<float>(mid, mid), kThermalPatchMax);
  // Out of the frame (the footprint is 17.9 x 14.3 m from 20 m): none.
  EXPECT_FALSE(ThermalPatchAt(v, Vector3d(8.5, 0, 0), &patch));
}

TEST(ThermalEvidence, AClassifierThatIsNoNetworkIsRefused) {
  EXPECT_FALSE(ThermalClassifier::FromOnnx("not an onnx file").ok());
  EXPECT_FALSE(ThermalClassifier::FromOnnx("").ok());
}

// A clear noon: the sun warms a dark backpack as much as clothing of its colour (physics_server
// thermal_test, ThermalScene), so the contrast hardly tells them apart; the shipped classifier, on
// the physics server's own thermal frame from the close look's 18 m, tells a lying person from the
// backpack 4 m north of them by shape.
TEST(ThermalEvidence, TheShippedClassifierTellsAPersonFromABackpackAsWarmAsTheirClothes) {
  const ThermalEvidence& e = ShippedThermalEvidence();
  ASSERT_GT(e.cnn_weight, 0.0);
  ASSERT_NE(e.cnn_onnx, nullptr);
  Result<std::unique_ptr<ThermalClassifier>> c = ThermalClassifier::FromOnnx(*e.cnn_onnx);
  ASSERT_TRUE(c.ok()) << c.error().ToString();
  const physics::Bgr dark_blue{120, 60, 30};
  physics::WorldConfig w;
  w.name = "thermal";
  w.lighting = physics::Lighting{12.0, 0.0, 20.0};
  w.terrain = physics::Terrain{physics::TerrainKind::kRubble, 0.0};
  w.victims.push_back({.id = "v", .x_m = 0.0, .y_m = 0.0, .heading_rad = 0.4, .clothing_bgr = dark_blue});
  w.distractors.push_back({.kind = physics::DistractorKind::kBackpack,
                           .x_m = 0.0,
                           .y_m = 4.0,
                           .heading_rad = 0.0,
                           .size_m = 0.6,
                           .colour_bgr = dark_blue});
  auto doc = yaml::ParseFile(std::string(SWARMBOX_TRIALS_DIR) + "/sensors/boson_320_thermal.yaml");
  ASSERT_TRUE(doc.ok()) << doc.error().ToString();
  auto spec = airframe::ParseThermalSpec(doc->Find("thermal"));
  ASSERT_TRUE(spec.ok()) << spec.error().ToString();
  physics::ThermalRenderer renderer(w);
  physics::ThermalImage img;
  renderer.Render(physics::Pose{physics::Vec3{0, 2, 18}, physics::Quat{}}, *spec, 7, &img);
  const ThermalView view = perception_scenes::ThermalViewOf(img);
  cv::Mat person, backpack;
  ASSERT_TRUE(ThermalPatchAt(view, Vector3d(0, 0, 0), &person));
  ASSERT_TRUE(ThermalPatchAt(view, Vector3d(0, 4, 0), &backpack));
  const std::optional<double> cp = ThermalContrastAt(view, Vector3d(0, 0, 0), e.radius_m);
  const std::optional<double> cb = ThermalContrastAt(view, Vector3d(0, 4, 0), e.radius_m);
  ASSERT_TRUE(cp && cb);
  EXPECT_LT(std::abs(*cp - *cb), 0.25 * *cp) << "the contrasts " << *cp << " and " << *cb << " K";
  const double lp = (*c)->Logit(person), lb = (*c)->Logit(backpack);
  EXPECT_GT(lp, 0.0);
  EXPECT_LT(lb, 0.0);
  EXPECT_GT(e.Fuse(0.7, *cp, lp), e.Fuse(0.7, *cb, lb) + 0.3);
}

TEST(ThermalEvidence, TheFusionIsALogisticOfBothAndClampsTheContrast) {
  const ThermalEvidence e = Evidence(0.8, 0.2, -1.0);
  auto logit = [](double p) { return std::log(p / (1 - p)); };
  EXPECT_NEAR(logit(e.Fuse(0.9, 5.0)), 0.8 * logit(0.9) + 0.2 * 5.0 - 1.0, 1e-9);
  EXPECT_GT(e.Fuse(0.6, 15.0), e.Fuse(0.6, 2.0));
  EXPECT_GT(e.Fuse(0.9, 5.0), e.Fuse(0.6, 5.0));
  EXPECT_DOUBLE_EQ(e.Fuse(0.7, 1000.0), e.Fuse(0.7, kMaxContrastK));
  EXPECT_DOUBLE_EQ(e.Fuse(0.7, -1000.0), e.Fuse(0.7, kMinContrastK));
  // The defaults leave a confidence as it was.
  EXPECT_NEAR(ThermalEvidence{}.Fuse(0.73, 12.0), 0.73, 1e-12);
  // With a classifier its logit adds, weighted and clamped.
  ThermalEvidence c = e;
  c.cnn_weight = 0.5;
  EXPECT_NEAR(logit(c.Fuse(0.9, 5.0, 3.0)), 0.8 * logit(0.9) + 0.2 * 5.0 + 0.5 * 3.0 - 1.0, 1e-9);
  EXPECT_DOUBLE_EQ(c.Fuse(0.9, 5.0, 1e6), c.Fuse(0.9, 5.0, kMaxCnnLogit));
  EXPECT_DOUBLE_EQ(e.Fuse(0.9, 5.0, 3.0), e.Fuse(0.9, 5.0));  // cnn_weight 0: no classifier
}

// The shipped fit (models/thermal_evidence.yaml): a person's shape by the classifier is more likely
// a person, and it weighs most (tools/train_detector/README.md "A thermal classifier"): what the
// thermal frame shows decides a candidate it sees.
TEST(ThermalEvidence, TheShippedFitSaysWhatLooksLikeAPersonInThermalIsMoreLikelyOne) {
  const ThermalEvidence& e = ShippedThermalEvidence();
  EXPECT_GE(e.slope_per_k, 0.0);
  EXPECT_GE(e.colour_weight, 0.0);
  EXPECT_GT(e.cnn_weight, 0.5);
  EXPECT_EQ(e.cnn_model, "thermal_cnn.onnx");
  EXPECT_GT(e.radius_m, 0.3);
  EXPECT_GT(e.Fuse(0.6, 10.0, 4.0), 0.9);
  EXPECT_LT(e.Fuse(0.9, 10.0, -4.0), 0.1);
  EXPECT_GE(e.Fuse(0.9, 10.0, 0.0), e.Fuse(0.6, 10.0, 0.0));
}

TEST(ThermalEvidence, AFitWithoutItsFiguresIsRefused) {
  auto parse = [](const char* text) {
    auto root = yaml::Parse(text, "thermal_evidence.yaml");
    EXPECT_TRUE(root.ok());
    return ParseThermalEvidence(*root);
  };
  EXPECT_TRUE(parse("thermal_evidence: {colour_weight: 0.8, slope_per_k: 0.2, bias: -1, radius_m: 0.7, fit: "
                    "{seed: 1}}\n")
                  .ok());
  EXPECT_FALSE(parse("thermal_evidence: {colour_weight: 0.8, slope_per_k: 0.2, radius_m: 0.7}\n").ok());
  EXPECT_FALSE(
      parse("thermal_evidence: {colour_weight: 0.8, slope_per_k: -0.2, bias: -1, radius_m: 0.7}\n").ok());
  EXPECT_FALSE(
      parse("thermal_evidence: {colour_weight: 0, slope_per_k: 0.2, bias: -1, radius_m: 0.7}\n").ok());
  EXPECT_FALSE(
      parse(
          "thermal_evidence: {colour_weight: 0.8, slope_per_k: 0.2, bias: -1, radius_m: 0.7, colour: red}\n")
          .ok());
  EXPECT_FALSE(parse("other: 1\n").ok());
  // A classifier's weight needs its network's name, and the name a weight.
  const Result<ThermalEvidence> with = parse(
      "thermal_evidence: {colour_weight: 0.8, slope_per_k: 0.0, bias: -1, radius_m: 0.7, cnn_weight: 0.6, "
      "cnn_model: "
      "thermal_cnn.onnx}\n");
  ASSERT_TRUE(with.ok()) << with.error().ToString();
  EXPECT_DOUBLE_EQ(with->cnn_weight, 0.6);
  EXPECT_EQ(with->cnn_model, "thermal_cnn.onnx");
  EXPECT_EQ(with->cnn_onnx, nullptr);  // the caller loads it
  EXPECT_FALSE(
      parse("thermal_evidence: {colour_weight: 0.8, slope_per_k: 0.2, bias: -1, radius_m: 0.7, cnn_weight: "
            "0.6}\n")
          .ok());
  EXPECT_FALSE(
      parse("thermal_evidence: {colour_weight: 0.8, slope_per_k: 0.2, bias: -1, radius_m: 0.7, cnn_model: "
            "x.onnx}\n")
          .ok());
}

// A rendered colour frame with one person, and thermal frames taken with it: each gives the fused
// confidence of its contrast there (warm where the person lies, none on a flat field), and a frame
// that does not see the point leaves it as the colour detector gave it.
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
  params.thermal = Evidence(0.8, 0.2, -1.0);
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
  EXPECT_NEAR(*contrast, 10.0, 1e-3);
  EXPECT_NEAR(b[0].confidence, params.thermal.Fuse(rgb, *contrast), 1e-12);
  EXPECT_DOUBLE_EQ(c[0].confidence, rgb);
  // Flat: no contrast: the confidence is what the colour detector's alone is worth to the fit.
  ASSERT_EQ(flat.ProcessFrame(bgr, s->intrinsics, s->true_pose, 5.0, nullptr, &flat_view), 1);
  std::vector<GroundDetection> d;
  flat.PopVisible(10.0, &d);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_NEAR(d[0].confidence, params.thermal.Fuse(rgb, 0.0), 1e-12);
  EXPECT_GT(b[0].confidence, d[0].confidence);

  // With the shipped evidence and its classifier: the classifier's logit on the patch there.
  params.thermal = ShippedThermalEvidence();
  VictimPerception shipped(params);
  ASSERT_EQ(shipped.ProcessFrame(bgr, s->intrinsics, s->true_pose, 5.0, nullptr, &warm_view), 1);
  std::vector<GroundDetection> e;
  shipped.PopVisible(10.0, &e);
  ASSERT_EQ(e.size(), 1u);
  cv::Mat patch;
  ASSERT_TRUE(ThermalPatchAt(warm_view, e[0].position_m, &patch));
  Result<std::unique_ptr<ThermalClassifier>> classifier =
      ThermalClassifier::FromOnnx(*params.thermal.cnn_onnx);
  ASSERT_TRUE(classifier.ok());
  EXPECT_NEAR(e[0].confidence, params.thermal.Fuse(rgb, *contrast, (*classifier)->Logit(patch)), 1e-9);
}

}  // namespace
}  // namespace swarmbox::swarm
