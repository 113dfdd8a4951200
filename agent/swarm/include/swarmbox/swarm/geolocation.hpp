// Geolocation: from a pixel of the downward camera to a point on the ground, by casting the pixel's
// ray through the pinhole model with the camera's (estimated) pose onto the plane z = ground_z_m.
//
//   const OpticalPose cam = OpticalPoseFromBody(est.pos_m, est.att, camera_offset_body_m);
//   std::optional<Eigen::Vector3d> p = PixelToGround({u, v}, intrinsics, cam, /*ground_z_m=*/0.0);
//
// Camera conventions (bus::CameraImage, physics camera_image.hpp): the optical frame is OpenCV's
// (x right, y down, z along the optical axis); the downward camera looks along body -z with image
// up = body +x, i.e. x_opt = -y_body, y_opt = -x_body, z_opt = -z_body. A point p_opt lands at
// u = fx x/z + cx, v = fy y/z + cy (no distortion: the simulated camera has none).
#pragma once

#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace swarmbox::swarm {

struct PinholeIntrinsics {
  double fx_px = 0, fy_px = 0, cx_px = 0, cy_px = 0;
};

// Pose of the optical frame: position in world ENU [m] and rotation optical -> world.
struct OpticalPose {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};

// Rotation body FLU -> optical-frame axes of the downward camera (constant).
Eigen::Matrix3d BodyFromOptical();

// The camera's optical pose from a body pose (body -> world) and the camera centre in the body
// frame [m] (airframe camera offset_m).
OpticalPose OpticalPoseFromBody(const Eigen::Vector3d& body_position_m,
                                const Eigen::Quaterniond& body_to_world,
                                const Eigen::Vector3d& camera_offset_body_m);

// The ray direction (unit, world ENU) through pixel (u, v).
Eigen::Vector3d PixelRay(const Eigen::Vector2d& pixel, const PinholeIntrinsics& k,
                         const OpticalPose& pose);

// Where the ray through `pixel` meets the plane z = ground_z_m; nullopt if the ray does not point
// down toward it (horizon or above).
std::optional<Eigen::Vector3d> PixelToGround(const Eigen::Vector2d& pixel, const PinholeIntrinsics& k,
                                             const OpticalPose& pose, double ground_z_m);

// Projects a world point into the image; nullopt behind the camera.
std::optional<Eigen::Vector2d> ProjectToPixel(const Eigen::Vector3d& point_m,
                                              const PinholeIntrinsics& k, const OpticalPose& pose);

// 1-sigma horizontal uncertainty of a ground point at slant range `range_m` [m], from the pose's
// position uncertainty [m], attitude uncertainty [rad] and the pixel uncertainty [px] at focal
// length fx_px. Independent errors, added in quadrature (small-angle).
double GroundSigma(double range_m, double position_sigma_m, double attitude_sigma_rad,
                   double pixel_sigma_px, double fx_px);

}  // namespace swarmbox::swarm
