// The stereo pair: the `stereo:` airframe key (ParseStereoSpec) and the ray-cast renderer's
// parallax, truth depth and projector dots.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "swarmbox/physics/stereo_renderer.hpp"
#include "swarmbox/physics/stereo_scene.hpp"
#include "swarmbox/physics/stereo_spec.hpp"
#include "swarmbox/physics/world_config.hpp"
#include "swarmbox/physics/world_scene.hpp"

namespace swarmbox::physics {
namespace {

Result<StereoSpec> ParseText(const std::string& text) {
  auto doc = yaml::Parse(text, "af.yaml");
  if (!doc) return doc.error();
  return ParseStereoSpec(doc->Find("stereo"));
}

TEST(StereoSpec, AbsentKeyIsOffAndCostsNothing) {
  auto spec = ParseText("name: x\n");
  ASSERT_TRUE(spec.ok()) << spec.error().ToString();
  EXPECT_FALSE(spec->enabled);
  auto null_spec = ParseStereoSpec(nullptr);
  ASSERT_TRUE(null_spec.ok());
  EXPECT_FALSE(null_spec->enabled);
}

TEST(StereoSpec, ReferenceFileIsTheOakDProDatasheet) {
  auto doc = yaml::ParseFile(std::string(SWARMBOX_TRIALS_DIR) + "/sensors/oak_d_pro_stereo.yaml");
  ASSERT_TRUE(doc.ok()) << doc.error().ToString();
  auto spec = ParseStereoSpec(doc->Find("stereo"));
  ASSERT_TRUE(spec.ok()) << spec.error().ToString();
  EXPECT_TRUE(spec->enabled);
  EXPECT_DOUBLE_EQ(spec->baseline_m, 0.075);  // REFERENCES.md 2.1 [C1]: 75 mm
  EXPECT_EQ(spec->width_px, 640);             // 1280 x 800 halved
  EXPECT_EQ(spec->height_px, 400);
  // f = 882.5 px at 800P [C3], halved: 441 px within a pixel.
  EXPECT_NEAR(spec->FocalPx(), 882.5 / 2, 1.0);
  EXPECT_NEAR(spec->projector.foi_h_rad * 180 / M_PI, 78.0, 0.1);  // Belago1.1 FOI [C4]
  EXPECT_NEAR(spec->projector.foi_v_rad * 180 / M_PI, 61.0, 0.1);
  EXPECT_DOUBLE_EQ(spec->latency_min_ms, 30);
  EXPECT_DOUBLE_EQ(spec->latency_max_ms, 50);
}

TEST(StereoSpec, EnabledFalseInsideTheMappingTurnsItOff) {
  auto spec = ParseText("stereo: {enabled: false, baseline_m: 0.1}\n");
  ASSERT_TRUE(spec.ok()) << spec.error().ToString();
  EXPECT_FALSE(spec->enabled);
  EXPECT_DOUBLE_EQ(spec->baseline_m, 0.1);
}

TEST(StereoSpec, ErrorsNameTheKeyAndWhere) {
  struct Case {
    const char* yaml;
    const char* message;
  };
  const Case cases[] = {
      {"stereo: {baseline_m: -1}\n", "'baseline_m' must be > 0"},
      {"stereo: {colour: true}\n", "colour"},
      {"stereo: {num_disparities: 40}\n", "multiple of 16"},
      {"stereo: {latency_min_ms: 50, latency_max_ms: 30}\n", "latency_max_ms must be >= latency_min_ms"},
      {"stereo: {projector: {pattern: stripes}}\n", "pattern must be 'dots'"},
      {"stereo: {projector: {dot_fill: 0.7}}\n", "dot_fill must be below 0.5"},
      {"stereo: {width_px: 8}\n", "32..4096"},
  };
  for (const Case& c : cases) {
    auto spec = ParseText(c.yaml);
    ASSERT_FALSE(spec.ok()) << c.yaml;
    EXPECT_NE(spec.error().ToString().find(c.message), std::string::npos) << spec.error().ToString();
    EXPECT_NE(spec.error().ToString().find("af.yaml:1:"), std::string::npos) << spec.error().ToString();
  }
}

// A dark flat ground with a bright 2 m x 2 m box 2 m tall at the origin and a bright 1 m patch
// on the ground at y = -3 (image right), seen from 10 m straight down.
class StereoParallax : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = MakeSurfaceScene(StereoSurface::kConcreteShade, 30.0, 1);
    scene_.albedo.setTo(0.1);
    AddBox(&scene_, {0, 0, 0}, {2, 2, 0}, 2.0, 0.9);
    AddBox(&scene_, {0, -3, 0}, {1, 1, 0}, 0.0, 0.9);
    spec_.enabled = true;
    spec_.noise_std = 0;
    spec_.offset_m = {0, 0, 0};
    spec_.projector.enabled = false;
    body_.position_m = {0, 0, 10};
  }
  // First column from `from` on the middle row where the image turns bright.
  static double RisingEdge(const cv::Mat& img, int from) {
    const int v = img.rows / 2;
    for (int u = from; u < img.cols; ++u) {
      if (img.at<std::uint8_t>(v, u) > 128) return u;
    }
    return -1;
  }
  StereoScene scene_;
  StereoSpec spec_;
  Pose body_;
};

TEST_F(StereoParallax, ABoxShiftsByFocalTimesBaselineOverItsDepth) {
  spec_.baseline_m = 0.5;  // a wide baseline so the disparities are tens of pixels
  StereoRenderer renderer(&scene_);
  StereoFrame frame;
  renderer.Render(body_, spec_, 1, &frame);
  const double f = spec_.FocalPx();
  // The box top is 8 m away, the ground 10 m.
  EXPECT_NEAR(frame.depth_truth_m.at<float>(spec_.height_px / 2, spec_.width_px / 2), 8.0, 0.02);
  EXPECT_NEAR(frame.depth_truth_m.at<float>(5, 5), 10.0, 0.02);
  const double box_l = RisingEdge(frame.left, 0), box_r = RisingEdge(frame.right, 0);
  ASSERT_GT(box_l, 0);
  ASSERT_GT(box_r, 0);
  EXPECT_NEAR(box_l - box_r, f * spec_.baseline_m / 8.0, 1.5);  // 27.6 px
  // The patch on the ground (right of the box) shifts less: 22.1 px.
  const double patch_l = RisingEdge(frame.left, spec_.width_px / 2 + 120);
  const double patch_r = RisingEdge(frame.right, spec_.width_px / 2 + 100);
  ASSERT_GT(patch_l, 0);
  ASSERT_GT(patch_r, 0);
  // (Each view's edge is whole pixels: the difference is within +-1 px, plus the 5 cm cells.)
  EXPECT_NEAR(patch_l - patch_r, f * spec_.baseline_m / 10.0, 1.5);
}

TEST_F(StereoParallax, TheOakBaselineGivesSubPixelDisparitiesFarAway) {
  StereoRenderer renderer(&scene_);
  StereoFrame frame;
  renderer.Render(body_, spec_, 1, &frame);
  EXPECT_NEAR(frame.baseline_m, 0.075, 1e-12);
  // 441 px * 0.075 m / 8 m = 4.1 px: the edges move by 4 or 5 whole pixels.
  const double shift = RisingEdge(frame.left, 0) - RisingEdge(frame.right, 0);
  EXPECT_GE(shift, 3);
  EXPECT_LE(shift, 5);
}

// Mean absolute difference of the two views of a textureless slab in shade: the projector's dots
// make them differ from a flat grey, more near than far, and the sun drowns them.
double DotContrast(StereoSurface surface, double range_m, bool projector) {
  StereoScene scene = MakeSurfaceScene(surface, 40.0, 3);
  StereoSpec spec;
  spec.enabled = true;
  spec.noise_std = 0;
  spec.projector.enabled = projector;
  Pose body;
  body.position_m = {0, 0, range_m + scene.max_height_m};
  StereoRenderer renderer(&scene);
  StereoFrame frame;
  renderer.Render(body, spec, 1, &frame);
  cv::Scalar mean, stddev;
  cv::meanStdDev(frame.left, mean, stddev);
  return stddev[0] / std::max(1.0, mean[0]);
}

TEST(StereoRenderer, DotsFadeWithDistanceAndDrownInSunlight) {
  const double shade_off = DotContrast(StereoSurface::kConcreteShade, 5, false);
  const double shade_near = DotContrast(StereoSurface::kConcreteShade, 3, true);
  const double shade_far = DotContrast(StereoSurface::kConcreteShade, 15, true);
  const double sun_near = DotContrast(StereoSurface::kSandSun, 3, true);
  EXPECT_LT(shade_off, 0.03);           // the slab alone: a 1 % ripple
  // At 3 m a dot is ~0.49 W/m^2 (0.3 W / (1.37 sr * 9 m^2 * 0.05)), 80 % of the shade's 0.6
  // W/m^2, on 5 % of the pixels: a relative std of ~0.18 (0.8 * sqrt(0.05)).
  EXPECT_GT(shade_near, 0.08);
  EXPECT_GT(shade_near, 3 * shade_far);  // inverse square
  EXPECT_LT(sun_near, shade_near / 4);   // full sun is ~20x the shade's ambient
}

TEST(StereoRenderer, SameSeedSameImages) {
  StereoScene scene = MakeSurfaceScene(StereoSurface::kRubble, 20.0, 5);
  StereoSpec spec;
  spec.enabled = true;
  Pose body;
  body.position_m = {1, 2, 6};
  body.attitude = Quat::FromYaw(0.4);
  StereoRenderer renderer(&scene);
  StereoFrame a, b;
  renderer.Render(body, spec, 9, &a);
  renderer.Render(body, spec, 9, &b);
  EXPECT_EQ(cv::norm(a.left, b.left, cv::NORM_L1), 0.0);
  EXPECT_EQ(cv::norm(a.right, b.right, cv::NORM_L1), 0.0);
  renderer.Render(body, spec, 10, &b);
  EXPECT_GT(cv::norm(a.left, b.left, cv::NORM_L1), 0.0);  // another noise draw
}

// The renderer's ray march as the reference, step for step: from the highest cell's level down in
// steps of about a cell (samples at t0 + k * dt), then a secant. A faster march (issue #23: a max-height pyramid that skips
// samples it proves above the surface) must give these depths to the bit, so that the images and
// the benchmark's figures do not change either.
double PlainMarch(const StereoScene& s, const Vec3& centre, const Vec3& d) {
  constexpr double kNearClip_m = 0.05, kEndMargin_m = 1e-3;  // stereo_renderer.cpp's
  const double t_end = (centre.z - s.min_height_m) / -d.z + kEndMargin_m;
  const double dt = s.cell_m / std::max(std::hypot(d.x, d.y), -d.z);
  const double t0 = std::max(kNearClip_m, (centre.z - s.max_height_m) / -d.z);
  double prev_t = t0, prev_f = 1.0;
  for (double k = 0;; ++k) {
    const double t = t0 + k * dt;
    if (!(t <= t_end + dt)) break;
    const double tt = std::min(t, t_end);
    const double fz = centre.z + tt * d.z - s.HeightAt(centre.x + tt * d.x, centre.y + tt * d.y);
    if (fz <= 0) return fz == prev_f ? tt : prev_t + (tt - prev_t) * prev_f / (prev_f - fz);
    prev_t = tt;
    prev_f = fz;
  }
  return t_end;
}

// Yaw about z, then roll about the body's x axis (a view tilted sideways by `roll_rad`).
Quat YawThenRoll(double yaw_rad, double roll_rad) {
  return {std::cos(yaw_rad / 2) * std::cos(roll_rad / 2), std::cos(yaw_rad / 2) * std::sin(roll_rad / 2),
          std::sin(yaw_rad / 2) * std::sin(roll_rad / 2), std::sin(yaw_rad / 2) * std::cos(roll_rad / 2)};
}

// The left view's pixels whose truth depth is not the reference march's through the same ray (the
// renderer's ray set-up, repeated), of `*compared` (the rays that look down).
int DepthsOffTheReferenceMarch(const StereoScene& scene, const Pose& body, const StereoSpec& spec, int* compared) {
  StereoRenderer renderer(&scene);
  StereoFrame frame;
  renderer.Render(body, spec, 1, &frame);
  const Vec3 ex = Rotate(body.attitude, Vec3{0, -1, 0}), ey = Rotate(body.attitude, Vec3{-1, 0, 0}),
             ez = Rotate(body.attitude, Vec3{0, 0, -1});
  const Vec3 left = body.position_m + Rotate(body.attitude, spec.offset_m) - ex * (spec.baseline_m / 2);
  const double f = spec.FocalPx(), cx = spec.width_px / 2.0, cy = spec.height_px / 2.0;
  int differ = 0;
  *compared = 0;
  for (int v = 0; v < spec.height_px; ++v) {
    for (int u = 0; u < spec.width_px; ++u) {
      const double xn = (u + 0.5 - cx) / f, yn = (v + 0.5 - cy) / f;
      const Vec3 d{ex.x * xn + ey.x * yn + ez.x, ex.y * xn + ey.y * yn + ez.y, ex.z * xn + ey.z * yn + ez.z};
      if (d.z > -1e-6) continue;  // the renderer's sky
      ++*compared;
      if (frame.depth_truth_m.at<float>(v, u) != static_cast<float>(PlainMarch(scene, left, d))) ++differ;
    }
  }
  return differ;
}

// Rubble (heaps, chunks, columns) seen obliquely from 2.5 m above its highest cell, so that rays
// graze heaps, pass over tiles of every pyramid level and leave the grid: every left pixel's
// truth depth is the reference march's through the same ray (the renderer's ray set-up, repeated).
TEST(StereoRenderer, TruthDepthIsTheReferenceMarchsToTheBit) {
  StereoScene scene = MakeSurfaceScene(StereoSurface::kRubble, 12.0, 5);
  AddBox(&scene, {1, -1, 0}, {0.5, 0.5, 0}, 3.0, 0.5);  // a column up past the camera's level
  scene.UpdateHeightRange();
  StereoSpec spec;
  spec.enabled = true;
  spec.width_px = 160;
  spec.height_px = 100;
  Pose body;
  body.position_m = {0.5, -0.3, scene.max_height_m + 2.5};
  body.attitude = YawThenRoll(/*yaw_rad=*/0.3, /*roll_rad=*/0.5);  // a tilted view
  int compared = 0;
  const int differ = DepthsOffTheReferenceMarch(scene, body, spec, &compared);
  EXPECT_GT(compared, spec.width_px * spec.height_px / 2);
  EXPECT_EQ(differ, 0) << "of " << compared << " pixels";
}

// A trial world's patch (MakeWorldScene) with obstacles far taller than the ground's relief, seen
// from 15 m: most of each ray's march lies above its tile's highest cell (skipped samples), and
// every left pixel's truth depth is still the reference march's.
TEST(StereoRenderer, TruthDepthOverAWorldPatchIsTheReferenceMarchsToTheBit) {
  WorldConfig world;
  world.terrain = Terrain{TerrainKind::kRubble, 0.0};
  world.obstacles.push_back({"wall", {0, 6, 4}, {20, 1, 8}, 0.2, ObstacleKind::kBox});
  world.obstacles.push_back({"block", {-4, -3, 6}, {4, 4, 12}, 0.7, ObstacleKind::kBox});
  const StereoScene scene = MakeWorldScene(world, 0, 0, 15, 3);
  StereoSpec spec;
  spec.enabled = true;
  spec.width_px = 160;
  spec.height_px = 100;
  Pose body;
  body.position_m = {1.0, 0.5, 15.0};
  int compared = 0;
  const int differ = DepthsOffTheReferenceMarch(scene, body, spec, &compared);
  EXPECT_EQ(compared, spec.width_px * spec.height_px);  // straight down: every ray meets the ground
  StereoRenderer renderer(&scene);
  StereoFrame frame;
  renderer.Render(body, spec, 1, &frame);
  const int on_obstacles = cv::countNonZero(frame.depth_truth_m < 12.0f);  // the wall's or the block's top
  EXPECT_EQ(differ, 0) << "of " << spec.width_px * spec.height_px << " pixels";
  EXPECT_GT(on_obstacles, 100);
}

// The march's empty-space jumps (over tiles whose highest cell is far below the ray) over tall
// columns: tree_lines' 26 m woodland strips and a rubble field with 26 m columns from one cell to
// 3 m wide (edges on and off the 0.4 m tiles' edges), seen straight down from 4 and 30 m over the
// crowns, from below the crowns, tilted up to 70 degrees (rays a tile long per few centimetres of
// descent, and rays that leave the grid, where its border cells stand on) and from outside the
// grid. Every left pixel's truth depth is the reference march's, sample for sample.
TEST(StereoRenderer, TruthDepthOverTallColumnsIsTheReferenceMarchsToTheBit) {
  auto woods = LoadWorld(std::string(SWARMBOX_TRIALS_DIR) + "/worlds/tree_lines.yaml");
  ASSERT_TRUE(woods.ok()) << woods.error().ToString();
  const StereoScene meadow = MakeWorldScene(*woods, 0, 0, 30, woods->ground_texture_seed);
  StereoScene columns = MakeSurfaceScene(StereoSurface::kRubble, 24.0, 9);
  constexpr double kCrown_m = 26.0;
  AddBox(&columns, {3, 2, 0}, {3, 3, 0}, kCrown_m, 0.3);
  AddBox(&columns, {-4.1, 1.3, 0}, {1.1, 0.7, 0}, kCrown_m, 0.3);
  AddBox(&columns, {0.6, -3.3, 0}, {0.05, 0.05, 0}, kCrown_m, 0.3);  // one cell
  AddBox(&columns, {-2, -6, 0}, {20, 0.4, 0}, kCrown_m - 6, 0.3);      // a wall on tile edges
  AddBox(&columns, {11.8, 0, 0}, {0.4, 24, 0}, kCrown_m, 0.3);          // along the grid's border
  columns.UpdateHeightRange();
  StereoSpec spec;
  spec.enabled = true;
  spec.width_px = 320;
  spec.height_px = 200;
  struct View {
    const char* name;
    const StereoScene* scene;
    Vec3 position_m;
    double yaw_rad, roll_rad;
  };
  const View views[] = {
      {"meadow, straight down from 30 m", &meadow, {0, 0, 30}, 0, 0},
      {"meadow, 4 m over the crowns, tilted", &meadow, {18, -3, 30}, 0.4, 0.7},
      {"meadow, below the crowns, tilted 70 deg", &meadow, {8, 5, 10}, 2.0, 1.2},
      {"columns, straight down from 30 m", &columns, {0.3, -0.2, 30}, 0, 0},
      {"columns, 4 m over the crowns, tilted", &columns, {-1, 1, 30}, -0.3, 0.6},
      {"columns, below the crowns towards the border", &columns, {6, -1, 8}, 1.5, 1.1},
      {"columns, from outside the grid", &columns, {16, 3, 28}, 0.0, -0.9},
  };
  for (const View& view : views) {
    Pose body;
    body.position_m = view.position_m;
    body.attitude = YawThenRoll(view.yaw_rad, view.roll_rad);
    int compared = 0;
    EXPECT_EQ(DepthsOffTheReferenceMarch(*view.scene, body, spec, &compared), 0) << view.name << ", of " << compared;
    EXPECT_GT(compared, spec.width_px * spec.height_px / 3) << view.name;
  }
}

// Bodies over the height field (StereoScene::boxes): a 2 x 0.6 x 0.25 m stretcher-sized box
// hanging level with its top 4 m under a camera 10 m over flat concrete.
class StereoBoxes : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = MakeSurfaceScene(StereoSurface::kConcreteShade, 30.0, 1);
    spec_.enabled = true;
    spec_.width_px = 160;
    spec_.height_px = 100;
    spec_.offset_m = {0, 0, 0};
    body_.position_m = {0, 0, 10};
    box_ = {.centre_m = {0, 0, 6 - 0.125}, .attitude = {}, .half_size_m = {1.0, 0.3, 0.125}, .albedo = 0.45,
            .texture_seed = 3};
  }
  StereoFrame Render(const StereoScene& scene) {
    StereoRenderer renderer(&scene);
    StereoFrame frame;
    renderer.Render(body_, spec_, 4, &frame);
    return frame;
  }
  StereoScene scene_;
  StereoSpec spec_;
  Pose body_;
  SceneBox box_;
};

// Down the optical axis of the left camera (half the baseline beside the box's centre line): the
// box's top, 4 m away; a ray past the box's end still sees the ground 10 m away.
TEST_F(StereoBoxes, ARayStraightDownOntoABoxSeesItsTop) {
  scene_.boxes.push_back(box_);
  const StereoFrame frame = Render(scene_);
  const int u = spec_.width_px / 2, v = spec_.height_px / 2;
  EXPECT_NEAR(frame.depth_truth_m.at<float>(v, u), 4.0, 1e-4);
  EXPECT_NEAR(frame.depth_truth_m.at<float>(0, u), 10.0, 1e-3);  // the top row looks past the box's end
  int on_box = 0;
  for (int r = 0; r < frame.depth_truth_m.rows; ++r) {
    for (int c = 0; c < frame.depth_truth_m.cols; ++c) on_box += frame.depth_truth_m.at<float>(r, c) < 5.0f;
  }
  // The box's top covers 2.0 x 0.6 m at 4 m: (f * 2.0 / 4) x (f * 0.6 / 4) pixels.
  const double f = spec_.FocalPx();
  EXPECT_NEAR(on_box, (f * 2.0 / 4) * (f * 0.6 / 4), 0.15 * (f * 2.0 / 4) * (f * 0.6 / 4));
}

// A tilted box hit from above at a known point: its top face's plane, as the truth depth says.
TEST_F(StereoBoxes, ATiltedBoxIsHitOnItsTiltedFace) {
  const double roll = 0.3;  // about the box's x axis: its top's normal tips towards -y
  box_.attitude = {std::cos(roll / 2), std::sin(roll / 2), 0, 0};
  scene_.boxes.push_back(box_);
  const StereoFrame frame = Render(scene_);
  const int u = spec_.width_px / 2, v = spec_.height_px / 2;
  // The centre pixel's ray from the left camera (0, B/2, 10): optical x is world -y, so the ray is
  // (-yn, -xn, -1) t with xn = yn = 0.5 / f. The top face: -sin(roll) y + cos(roll) (z - cz) = half_z.
  const double xn = 0.5 / spec_.FocalPx(), y0 = spec_.baseline_m / 2, sn = std::sin(roll), cs = std::cos(roll);
  const double t = (cs * (10 - box_.centre_m.z) - box_.half_size_m.z - sn * y0) / (cs - sn * xn);
  EXPECT_NEAR(frame.depth_truth_m.at<float>(v, u), t, 1e-4);
}

// A box outside the view (beside the patch, or above the camera) changes nothing, to the bit.
TEST_F(StereoBoxes, ABoxOutsideTheViewChangesNothing) {
  const StereoFrame plain = Render(scene_);
  box_.centre_m = {40, 0, 1};
  scene_.boxes.push_back(box_);
  box_.centre_m = {0, 0, 12};
  scene_.boxes.push_back(box_);
  const StereoFrame with_boxes = Render(scene_);
  EXPECT_EQ(cv::norm(plain.left, with_boxes.left, cv::NORM_L1), 0.0);
  EXPECT_EQ(cv::norm(plain.right, with_boxes.right, cv::NORM_L1), 0.0);
  EXPECT_EQ(cv::norm(plain.depth_truth_m, with_boxes.depth_truth_m, cv::NORM_L1), 0.0);
}

// The box is drawn textured and lit like the ground: the dots land on it, and its pixels are
// not uniform (so that the matcher has texture on it).
TEST_F(StereoBoxes, ABoxIsTexturedAndLitByTheProjector) {
  scene_.boxes.push_back(box_);
  const StereoFrame lit = Render(scene_);
  spec_.projector.enabled = false;
  const StereoFrame dark = Render(scene_);
  const cv::Mat on_box = lit.depth_truth_m < 5.0f;
  cv::Scalar mean_lit, std_dark, mean_dark;
  mean_lit = cv::mean(lit.left, on_box);
  cv::meanStdDev(dark.left, mean_dark, std_dark, on_box);
  EXPECT_GT(mean_lit[0] / cv::mean(lit.left, ~on_box)[0], mean_dark[0] / cv::mean(dark.left, ~on_box)[0]);
  EXPECT_GT(std_dark[0], 2.0);
}

// Culling (MayBeInView): a box whose bounding sphere is beyond the patch's half size of the
// camera horizontally, or wholly above the camera, is not tested by any ray.
TEST(SceneBox, MayBeInViewCullsByPatchAndHeight) {
  const SceneBox box{.centre_m = {0, 0, 0}, .attitude = {}, .half_size_m = {1.0, 0.3, 0.125}, .albedo = 0.4};
  const double r = BoundingRadiusM(box);
  EXPECT_NEAR(r, std::sqrt(1.0 + 0.09 + 0.125 * 0.125), 1e-12);
  EXPECT_TRUE(MayBeInView(box, {0, 0, 8}, 12));
  EXPECT_TRUE(MayBeInView(box, {12 + r - 0.01, 0, 8}, 12));
  EXPECT_FALSE(MayBeInView(box, {12 + r + 0.01, 0, 8}, 12));
  EXPECT_FALSE(MayBeInView(box, {0, -(12 + r + 0.01), 8}, 12));
  EXPECT_TRUE(MayBeInView(box, {0, 0, r - 0.01}, 12));   // reaches below the camera
  EXPECT_FALSE(MayBeInView(box, {0, 0, -r - 0.01}, 12)); // wholly above it
}

}  // namespace
}  // namespace swarmbox::physics
