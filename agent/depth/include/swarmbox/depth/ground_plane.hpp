// The ground's height and slope under a footprint, from one depth image (issue #23: the lifter's
// descent near a victim checks the ground under the stretcher's 2.2 x 0.6 m footprint).
//
//   const bus::Pose camera = LeftCameraPose(body_pose, {.offset_body_m = {0, 0, -0.05}, .baseline_m = 0.075});
//   const GroundFit g = FitGroundPlane(depth_m, {.focal_px = f, .cx_px = w / 2.0, .cy_px = h / 2.0}, camera,
//                                      {.centre_x_m = x, .centre_y_m = y, .length_m = 2.2, .width_m = 0.6});
//   if (g.valid && g.slope_rad < kMaxSlope && g.rms_residual_m < kMaxRoughness) ...  // land here
//
// Each pixel with depth is back-projected through its centre, (u + 0.5 - cx) z / f, (v + 0.5 - cy)
// z / f, z in the left camera's optical frame (x right, y down, z forward; z the depth along the
// optical axis, as StereoMatcher and the renderer's truth give it), then into the world (ENU) by the
// camera's pose. The points whose (x, y) fall inside the footprint (a rectangle, its length along
// yaw_rad from east) are fitted by least squares with z = h + gx (x - xc) + gy (y - yc): h the
// ground's height at the footprint's centre, atan(|(gx, gy)|) its slope, the RMS of the residuals
// its roughness plus the depth noise. Pure: no I/O, no clock.
#pragma once

#include <array>

#include <opencv2/core.hpp>

#include "swarmbox/bus/messages.hpp"

namespace swarmbox::depth {

struct CameraIntrinsics {
  double focal_px = 0;
  double cx_px = 0;  // principal point, in the pixel-edge convention: pixel u's centre is u + 0.5
  double cy_px = 0;
};

// Where the stereo pair sits on the body (the airframe's `stereo:` offset_m and baseline_m).
struct StereoMount {
  std::array<double, 3> offset_body_m{0.0, 0.0, -0.05};  // centre of the pair, body FLU [m]
  double baseline_m = 0.075;
};

// A rectangle on the ground, world ENU.
struct Footprint {
  double centre_x_m = 0;
  double centre_y_m = 0;
  double length_m = 2.2;  // along yaw_rad
  double width_m = 0.6;
  double yaw_rad = 0;     // direction of the length, from east towards north
};

struct GroundFit {
  bool valid = false;         // at least min_points points and a well-posed fit
  int points = 0;             // pixels whose back-projection fell inside the footprint
  double height_m = 0;        // the plane's world z at the footprint's centre
  double gradient_x = 0;      // dz/dx of the plane (east)
  double gradient_y = 0;      // dz/dy (north)
  double slope_rad = 0;       // the plane's angle to the horizontal
  double rms_residual_m = 0;  // RMS of the points' heights about the plane
};

// The left camera's optical frame (position ENU, rotation optical -> world as w x y z) for the
// body's pose (FLU body -> ENU world): the cameras look along body -z, optical x = body -y,
// optical y = body -x, the left camera baseline/2 left of the pair's centre (airframe
// stereo_spec.hpp), as the physics renderer draws them.
bus::Pose LeftCameraPose(const bus::Pose& body, const StereoMount& mount);

// The least-squares plane under `footprint` from `depth_m` (CV_32F, 0 = no depth).
GroundFit FitGroundPlane(const cv::Mat& depth_m, const CameraIntrinsics& intrinsics, const bus::Pose& camera,
                         const Footprint& footprint, int min_points = 50);

}  // namespace swarmbox::depth
