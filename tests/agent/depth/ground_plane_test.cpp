// FitGroundPlane on a rendered scene: a flat slab of concrete in shade next to a ramp of known slope
// (rising 0.2 m per metre east, 0.6 m over 3 m), the stretcher's 2.2 x 0.6 m footprint on each,
// seen by the OAK-D Pro from 4 m with the projector on, the body rolled and yawed so that the
// camera's pose matters. On the renderer's true depth: the geometry (back-projection and pose).
// Not yet tested on StereoSGBM's depth (what the agent has): its bounds are still to be measured.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "swarmbox/depth/ground_plane.hpp"
#include "swarmbox/physics/stereo_renderer.hpp"

namespace swarmbox::depth {
namespace {

constexpr double kRampStartX_m = 0.5;   // the ramp rises east of here ...
constexpr double kRampEndX_m = 3.5;     // ... to a plateau here
constexpr double kRampGradient = 0.2;   // dz/dx: 11.3 deg, 0.6 m over the 3 m
constexpr double kRampHalfWidth_m = 3.0;
constexpr double kFlatCentreX_m = -2.0;
constexpr double kRampCentreX_m = 2.0;  // footprint x in [0.9, 3.1]: on the ramp
constexpr double kCameraHeight_m = 4.0;  // above the footprint's centre

physics::StereoScene RampScene() {
  physics::StereoScene scene = physics::MakeSurfaceScene(physics::StereoSurface::kConcreteShade, 30.0, 5);
  for (int row = 0; row < scene.height_m.rows; ++row) {
    const double y = scene.origin_y_m + row * scene.cell_m;
    if (std::abs(y) > kRampHalfWidth_m) continue;
    for (int col = 0; col < scene.height_m.cols; ++col) {
      const double x = std::clamp(scene.origin_x_m + col * scene.cell_m, kRampStartX_m, kRampEndX_m);
      scene.height_m.at<float>(row, col) = static_cast<float>((x - kRampStartX_m) * kRampGradient);
    }
  }
  scene.UpdateHeightRange();
  return scene;
}

bus::Pose ToBus(const physics::Pose& p) {
  return {{p.position_m.x, p.position_m.y, p.position_m.z}, {p.attitude.w, p.attitude.x, p.attitude.y, p.attitude.z}};
}

struct Views {
  physics::StereoFrame frame;
  bus::Pose camera;  // from the body pose, as the agent computes it
};

// The pair over (x, 0) from kCameraHeight_m above the ground there, rolled 0.1 rad, yawed 0.6 rad.
Views Look(const physics::StereoScene& scene, double x_m) {
  physics::StereoSpec spec;
  spec.enabled = true;
  physics::Pose body;
  body.position_m = {x_m, 0.0, scene.HeightAt(x_m, 0.0) + kCameraHeight_m};
  const double roll = 0.1, yaw = 0.6;  // q = yaw about z, then roll about body x
  body.attitude = {std::cos(yaw / 2) * std::cos(roll / 2), std::cos(yaw / 2) * std::sin(roll / 2),
                   std::sin(yaw / 2) * std::sin(roll / 2), std::sin(yaw / 2) * std::cos(roll / 2)};
  physics::StereoRenderer renderer(&scene);
  Views views;
  renderer.Render(body, spec, 3, &views.frame);
  views.camera = LeftCameraPose(ToBus(body), {.offset_body_m = {spec.offset_m.x, spec.offset_m.y, spec.offset_m.z},
                                              .baseline_m = spec.baseline_m});
  return views;
}

GroundFit Fit(const Views& views, const cv::Mat& depth_m, double centre_x_m) {
  const CameraIntrinsics k{views.frame.focal_px, views.frame.cx_px, views.frame.cy_px};
  return FitGroundPlane(depth_m, k, views.camera, {.centre_x_m = centre_x_m, .centre_y_m = 0.0});
}

constexpr double kDeg = M_PI / 180;

TEST(GroundPlane, TheCameraPoseFromTheBodyIsTheRenderersLeftCamera) {
  const physics::StereoScene scene = RampScene();
  const Views views = Look(scene, kRampCentreX_m);
  const physics::Pose& truth = views.frame.left_optical_pose;
  EXPECT_NEAR(views.camera.position_enu_m[0], truth.position_m.x, 1e-9);
  EXPECT_NEAR(views.camera.position_enu_m[1], truth.position_m.y, 1e-9);
  EXPECT_NEAR(views.camera.position_enu_m[2], truth.position_m.z, 1e-9);
  // The same rotation: q and -q alike.
  const auto& q = views.camera.orientation_wxyz;
  const double dot = q[0] * truth.attitude.w + q[1] * truth.attitude.x + q[2] * truth.attitude.y + q[3] * truth.attitude.z;
  EXPECT_NEAR(std::abs(dot), 1.0, 1e-9);
}

// On true depth the only errors are the renderer's (a secant on a plane is exact) and float
// rounding of the depth (1e-7 relative, 0.4 um at 4 m): millimetres and hundredths of a degree.
TEST(GroundPlane, OnTrueDepthTheFlatPatchIsFlatAndTheRampHasItsSlope) {
  const physics::StereoScene scene = RampScene();
  const Views flat = Look(scene, kFlatCentreX_m);
  const GroundFit f = Fit(flat, flat.frame.depth_truth_m, kFlatCentreX_m);
  ASSERT_TRUE(f.valid);
  EXPECT_GT(f.points, 1000);  // 1.32 m^2 at ~9 mm a pixel
  EXPECT_NEAR(f.height_m, 0.0, 0.005);
  EXPECT_LT(f.slope_rad, 0.1 * kDeg);
  EXPECT_LT(f.rms_residual_m, 0.005);
  const Views ramp = Look(scene, kRampCentreX_m);
  const GroundFit r = Fit(ramp, ramp.frame.depth_truth_m, kRampCentreX_m);
  ASSERT_TRUE(r.valid);
  EXPECT_NEAR(r.height_m, (kRampCentreX_m - kRampStartX_m) * kRampGradient, 0.005);  // 0.3 m
  EXPECT_NEAR(r.gradient_x, kRampGradient, 0.002);
  EXPECT_NEAR(r.gradient_y, 0.0, 0.002);
  EXPECT_NEAR(r.slope_rad, std::atan(kRampGradient), 0.1 * kDeg);
  EXPECT_LT(r.rms_residual_m, 0.005);
}

}  // namespace
}  // namespace swarmbox::depth
