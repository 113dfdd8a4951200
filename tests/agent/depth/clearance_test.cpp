// ClearanceBelow on rendered scenes: a scout's stereo camera level over flat ground with rubble's
// texture (in sun, so SGBM has something to match) from 8 and 12 m, over a 6 m tall box (a tree
// crown or a wall) under it at 12 m, and over ground 20 m down (beyond the 15 m range). On the
// renderer's true depth (the geometry: near-exact answers) and on StereoSGBM's depth of the
// rendered pair (what the agent has) over several seeded scenes; the tolerances are SGBM's
// measured errors at those ranges (BENCHMARKS.md "stereo"), the figures printed are in
// agent/depth/README.md.
#include "swarmbox/depth/clearance.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "swarmbox/depth/stereo_matcher.hpp"
#include "swarmbox/physics/stereo_renderer.hpp"

namespace swarmbox::depth {
namespace {

constexpr double kSceneSize_m = 48.0;
constexpr double kX_m = 0.7, kY_m = -1.2;  // the scout's position (off the scene's grid)
constexpr double kYaw_rad = 0.4;
constexpr double kBoxSize_m = 3.0, kBoxTop_m = 6.0;
constexpr std::uint64_t kSeeds[] = {3, 4, 5};
// The top is the top_cells-th highest cell median: on true depth a cell's median is the surface's
// height within a cell's tilt (flat here); 2 cm for the float depth.
constexpr double kTruthTolerance_m = 0.02;
// SGBM's top_z_m vs the truth, measured here (seeds 3-5): flat ground from 8 m +0.06..+0.18 m;
// from 12 m +1.16 m (the 25th highest cell median is the upper tail of the ground's depth error:
// SGBM's sub-pixel estimate at d = 2.8 px steps in 1/16 px, 0.24 m at 12 m; BENCHMARKS.md
// "stereo": median 0.77 m, p90 0.98 m at 12 m); the 6 m box's top 6 m below the camera +0.44 m
// (median 0.28, p90 0.50 at 6 m). All too HIGH: the clearance is underestimated, the safe side.
constexpr double kSgbmTolerance8m_m = 0.3;
constexpr double kSgbmTolerance12m_m = 1.3;
constexpr double kSgbmToleranceBox_m = 0.5;

// Rubble's texture on flat ground (heights zeroed).
physics::StereoScene FlatTexturedGround(std::uint64_t seed) {
  physics::StereoScene scene = physics::MakeSurfaceScene(physics::StereoSurface::kRubble, kSceneSize_m, seed);
  scene.height_m.setTo(0.0f);
  scene.UpdateHeightRange();
  return scene;
}

// A kBoxTop_m tall box under the scout, its top textured like the ground (AddBox paints one
// albedo, which in sun leaves SGBM nothing to match on the top; a crown has leaves).
physics::StereoScene BoxUnderScout(std::uint64_t seed) {
  physics::StereoScene scene = FlatTexturedGround(seed);
  const cv::Mat texture = scene.albedo.clone();
  physics::AddBox(&scene, {kX_m, kY_m, 0}, {kBoxSize_m, kBoxSize_m, 0}, kBoxTop_m, 0.4);
  texture.copyTo(scene.albedo);
  return scene;
}

bus::Pose ToBus(const physics::Pose& p) {
  return {{p.position_m.x, p.position_m.y, p.position_m.z},
          {p.attitude.w, p.attitude.x, p.attitude.y, p.attitude.z}};
}

struct Views {
  Clearance truth;
  Clearance sgbm;
};

// The pair from `height_m` over the ground at (kX_m, kY_m), level, yawed; ClearanceBelow on its
// true depth and on SGBM's.
Views Look(const physics::StereoScene& scene, double height_m, std::uint64_t seed, const char* what) {
  physics::StereoSpec spec;
  spec.enabled = true;
  physics::Pose body;
  body.position_m = {kX_m, kY_m, height_m};
  body.attitude = {std::cos(kYaw_rad / 2), 0.0, 0.0, std::sin(kYaw_rad / 2)};
  physics::StereoRenderer renderer(&scene);
  physics::StereoFrame frame;
  renderer.Render(body, spec, seed, &frame);
  const bus::Pose camera = LeftCameraPose(
      ToBus(body),
      {.offset_body_m = {spec.offset_m.x, spec.offset_m.y, spec.offset_m.z}, .baseline_m = spec.baseline_m});
  StereoMatcher matcher({.num_disparities = spec.num_disparities});
  cv::Mat sgbm_m;
  matcher.Compute(frame.left, frame.right, frame.focal_px, frame.baseline_m, &sgbm_m);
  const CameraIntrinsics k{frame.focal_px, frame.cx_px, frame.cy_px};
  const auto start = std::chrono::steady_clock::now();
  const Clearance sgbm = ClearanceBelow(sgbm_m, k, camera, {});
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  Views v{ClearanceBelow(frame.depth_truth_m, k, camera, {}), sgbm};
  std::printf(
      "%s seed %llu: camera z %.3f; truth valid=%d top %.3f clearance %.3f points %d; "
      "sgbm valid=%d top %.3f clearance %.3f points %d (%.1f ms)\n",
      what, static_cast<unsigned long long>(seed), camera.position_enu_m[2], v.truth.valid, v.truth.top_z_m,
      v.truth.clearance_m, v.truth.points, v.sgbm.valid, v.sgbm.top_z_m, v.sgbm.clearance_m, v.sgbm.points,
      ms);
  return v;
}

TEST(Clearance, FlatGroundFrom8m) {
  for (const std::uint64_t seed : kSeeds) {
    const Views v = Look(FlatTexturedGround(seed), 8.0, seed, "flat 8 m");
    ASSERT_TRUE(v.truth.valid);
    EXPECT_NEAR(v.truth.top_z_m, 0.0, kTruthTolerance_m);
    ASSERT_TRUE(v.sgbm.valid);
    EXPECT_NEAR(v.sgbm.top_z_m, 0.0, kSgbmTolerance8m_m);
  }
}

TEST(Clearance, FlatGroundFrom12m) {
  for (const std::uint64_t seed : kSeeds) {
    const Views v = Look(FlatTexturedGround(seed), 12.0, seed, "flat 12 m");
    ASSERT_TRUE(v.truth.valid);
    EXPECT_NEAR(v.truth.top_z_m, 0.0, kTruthTolerance_m);
    ASSERT_TRUE(v.sgbm.valid);
    EXPECT_NEAR(v.sgbm.top_z_m, 0.0, kSgbmTolerance12m_m);
    EXPECT_GT(v.sgbm.clearance_m, 12.0 - kSgbmTolerance12m_m - 0.1);
  }
}

TEST(Clearance, SixMetreBoxUnderTheScoutAt12m) {
  for (const std::uint64_t seed : kSeeds) {
    const Views v = Look(BoxUnderScout(seed), 12.0, seed, "box 12 m");
    ASSERT_TRUE(v.truth.valid);
    EXPECT_NEAR(v.truth.top_z_m, kBoxTop_m, kTruthTolerance_m);
    EXPECT_NEAR(v.truth.clearance_m, 12.0 - kBoxTop_m, 0.1);  // the left camera is 5 cm under the body
    ASSERT_TRUE(v.sgbm.valid);
    EXPECT_NEAR(v.sgbm.top_z_m, kBoxTop_m, kSgbmToleranceBox_m);
    EXPECT_NEAR(v.sgbm.clearance_m, 12.0 - kBoxTop_m, kSgbmToleranceBox_m + 0.1);
  }
}

// The top is the height a patch of top_cells cells (0.25 m^2) reaches: a 0.3 m pole (9 cells) is
// not it, a 1 m crown (100 cells) is. On true depth: the geometry alone.
TEST(Clearance, TheTopIsAPatchNotAPole) {
  constexpr double kPoleTop_m = 7.0, kCrownTop_m = 4.0;
  physics::StereoScene scene = FlatTexturedGround(kSeeds[0]);
  physics::AddBox(&scene, {kX_m + 2.0, kY_m, 0}, {0.3, 0.3, 0}, kPoleTop_m, 0.4);
  physics::AddBox(&scene, {kX_m - 2.0, kY_m + 1.0, 0}, {1.0, 1.0, 0}, kCrownTop_m, 0.4);
  const Views v = Look(scene, 12.0, kSeeds[0], "pole and crown 12 m");
  ASSERT_TRUE(v.truth.valid);
  EXPECT_NEAR(v.truth.top_z_m, kCrownTop_m, kTruthTolerance_m);
}

TEST(Clearance, GroundBeyondTheRangeIsInvalid) {
  for (const std::uint64_t seed : kSeeds) {
    const Views v = Look(FlatTexturedGround(seed), 20.0, seed, "flat 20 m");
    EXPECT_FALSE(v.truth.valid);
    EXPECT_EQ(v.truth.points, 0);
    EXPECT_FALSE(v.sgbm.valid);
  }
}

}  // namespace
}  // namespace swarmbox::depth
