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

// The height of the surface near a world point, where something has measured it (agent/app
// PerceptionHost: the drone's own depth camera, agent/depth DepthSurface); nullopt where it is not
// known. An interface so that geolocation stays free of the depth camera's types.
class GroundHeightSource {
 public:
  virtual ~GroundHeightSource() = default;
  // The surface's world z (ENU) [m] near (x_m, y_m), or nullopt.
  virtual std::optional<double> HeightNear(double x_m, double y_m) const = 0;
};

// How often PixelToSurface re-intersects the ray with the height found where it last landed.
// Each pass is a fixed-point step x <- ray(h(x)): on a flat-topped surface (a slab, a roof, the
// ground) the first is exact once the flat-plane point lies on the same surface, the second
// confirms it (or corrects a first height taken from a neighbouring surface); on a slope s the
// error shrinks by s tan(off-nadir angle) each pass: <= 0.58 x 0.68 = 0.39 for rubble's 30 deg
// flanks at the camera's edge (hfov 1.2 rad), so two passes leave <= 16 % of the flat-plane error,
// typically (0.3 x 0.4)^2 = 1.4 %, below the depth's own error beyond a few metres.
inline constexpr int kSurfaceRefinements = 2;

// Where the ray through `pixel` meets the surface `surface` describes: first the plane
// z = ground_z_m (PixelToGround), then kSurfaceRefinements times the plane at the surface's height
// where the ray last landed. A height that is not known (or not below the camera) ends the
// refinement at the last point. nullopt where PixelToGround has none.
// Not found: a surface the ray grazes past to land beyond it (a slab's near edge: the answer is then
// within height x tan(off-nadir angle) of the truth, as the flat plane's is).
std::optional<Eigen::Vector3d> PixelToSurface(const Eigen::Vector2d& pixel, const PinholeIntrinsics& k,
                                              const OpticalPose& pose, double ground_z_m,
                                              const GroundHeightSource& surface);

// Projects a world point into the image; nullopt behind the camera.
std::optional<Eigen::Vector2d> ProjectToPixel(const Eigen::Vector3d& point_m,
                                              const PinholeIntrinsics& k, const OpticalPose& pose);

// 1-sigma horizontal uncertainty of a ground point at slant range `range_m` [m], from the pose's
// position uncertainty [m], attitude uncertainty [rad] and the pixel uncertainty [px] at focal
// length fx_px. Independent errors, added in quadrature (small-angle).
double GroundSigma(double range_m, double position_sigma_m, double attitude_sigma_rad,
                   double pixel_sigma_px, double fx_px);

}  // namespace swarmbox::swarm
