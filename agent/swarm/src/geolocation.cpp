#include "swarmbox/swarm/geolocation.hpp"

#include <cmath>

namespace swarmbox::swarm {

Eigen::Matrix3d BodyFromOptical() {
  Eigen::Matrix3d m;
  // Columns: the optical axes expressed in the body frame.
  m << 0, -1, 0,  //
      -1, 0, 0,   //
      0, 0, -1;
  return m;
}

OpticalPose OpticalPoseFromBody(const Eigen::Vector3d& body_position_m,
                                const Eigen::Quaterniond& body_to_world,
                                const Eigen::Vector3d& camera_offset_body_m) {
  OpticalPose p;
  p.position_m = body_position_m + body_to_world * camera_offset_body_m;
  p.rotation = Eigen::Quaterniond(body_to_world.toRotationMatrix() * BodyFromOptical());
  p.rotation.normalize();
  return p;
}

Eigen::Vector3d PixelRay(const Eigen::Vector2d& pixel, const PinholeIntrinsics& k,
                         const OpticalPose& pose) {
  const Eigen::Vector3d d_opt((pixel.x() - k.cx_px) / k.fx_px, (pixel.y() - k.cy_px) / k.fy_px, 1.0);
  return (pose.rotation * d_opt).normalized();
}

std::optional<Eigen::Vector3d> PixelToGround(const Eigen::Vector2d& pixel, const PinholeIntrinsics& k,
                                             const OpticalPose& pose, double ground_z_m) {
  const Eigen::Vector3d d = PixelRay(pixel, k, pose);
  const double dz = ground_z_m - pose.position_m.z();
  if (d.z() > -1e-6 || dz >= 0) return std::nullopt;  // not looking down, or at/below the ground
  const double t = dz / d.z();
  return pose.position_m + t * d;
}

std::optional<Eigen::Vector3d> PixelToSurface(const Eigen::Vector2d& pixel, const PinholeIntrinsics& k,
                                              const OpticalPose& pose, double ground_z_m,
                                              const GroundHeightSource& surface) {
  std::optional<Eigen::Vector3d> p = PixelToGround(pixel, k, pose, ground_z_m);
  for (int i = 0; p && i < kSurfaceRefinements; ++i) {
    const std::optional<double> height_m = surface.HeightNear(p->x(), p->y());
    if (!height_m) break;
    const std::optional<Eigen::Vector3d> refined = PixelToGround(pixel, k, pose, *height_m);
    if (!refined) break;  // a height at or above the camera: a mismatch, not a surface under it
    p = refined;
  }
  return p;
}

std::optional<Eigen::Vector2d> ProjectToPixel(const Eigen::Vector3d& point_m,
                                              const PinholeIntrinsics& k, const OpticalPose& pose) {
  const Eigen::Vector3d p = pose.rotation.conjugate() * (point_m - pose.position_m);
  if (p.z() < 1e-6) return std::nullopt;
  return Eigen::Vector2d(k.fx_px * p.x() / p.z() + k.cx_px, k.fy_px * p.y() / p.z() + k.cy_px);
}

double GroundSigma(double range_m, double position_sigma_m, double attitude_sigma_rad,
                   double pixel_sigma_px, double fx_px) {
  const double a = range_m * attitude_sigma_rad;
  const double b = range_m * pixel_sigma_px / fx_px;
  return std::sqrt(position_sigma_m * position_sigma_m + a * a + b * b);
}

}  // namespace swarmbox::swarm
