#include "swarmbox/depth/ground_plane.hpp"

#include <cmath>
#include <vector>

namespace swarmbox::depth {
namespace {

using V3 = std::array<double, 3>;
using Q4 = std::array<double, 4>;  // w x y z

V3 Cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// v' = q v q^-1.
V3 Rotate(const Q4& q, const V3& v) {
  const V3 u{q[1], q[2], q[3]};
  const V3 t0 = Cross(u, v);
  const V3 t{2 * t0[0], 2 * t0[1], 2 * t0[2]};
  const V3 ut = Cross(u, t);
  return {v[0] + q[0] * t[0] + ut[0], v[1] + q[0] * t[1] + ut[1], v[2] + q[0] * t[2] + ut[2]};
}

Q4 Multiply(const Q4& a, const Q4& b) {
  return {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3], a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
          a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1], a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
}

// Optical -> body: a half turn about (1, -1, 0) / sqrt(2), taking optical x, y, z to body -y, -x, -z.
const Q4 kOpticalToBody{0.0, M_SQRT1_2, -M_SQRT1_2, 0.0};

// A footprint point: offsets from the footprint's centre [m] and the height [m].
struct GroundPoint {
  double dx_m, dy_m, z_m;
};

// The pixels with depth whose back-projection lands inside the footprint.
std::vector<GroundPoint> PointsInFootprint(const cv::Mat& depth_m, const CameraIntrinsics& k, const bus::Pose& camera,
                                           const Footprint& fp) {
  const Q4& q = camera.orientation_wxyz;
  const V3& c = camera.position_enu_m;
  const double along_x = std::cos(fp.yaw_rad), along_y = std::sin(fp.yaw_rad);
  std::vector<GroundPoint> points;
  for (int v = 0; v < depth_m.rows; ++v) {
    const auto* row = depth_m.ptr<float>(v);
    for (int u = 0; u < depth_m.cols; ++u) {
      const double z = row[u];
      if (!(z > 0)) continue;
      const V3 w = Rotate(q, {(u + 0.5 - k.cx_px) * z / k.focal_px, (v + 0.5 - k.cy_px) * z / k.focal_px, z});
      const double dx = c[0] + w[0] - fp.centre_x_m, dy = c[1] + w[1] - fp.centre_y_m;
      const double along = dx * along_x + dy * along_y, across = -dx * along_y + dy * along_x;
      if (std::abs(along) <= fp.length_m / 2 && std::abs(across) <= fp.width_m / 2) {
        points.push_back({dx, dy, c[2] + w[2]});
      }
    }
  }
  return points;
}

}  // namespace

bus::Pose LeftCameraPose(const bus::Pose& body, const StereoMount& mount) {
  const Q4& q = body.orientation_wxyz;
  const V3 offset = Rotate(q, mount.offset_body_m);
  const V3 optical_x = Rotate(q, {0.0, -1.0, 0.0});
  bus::Pose camera;
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    camera.position_enu_m[k] = body.position_enu_m[k] + offset[k] - optical_x[k] * mount.baseline_m / 2;
  }
  camera.orientation_wxyz = Multiply(q, kOpticalToBody);
  return camera;
}

GroundFit FitGroundPlane(const cv::Mat& depth_m, const CameraIntrinsics& intrinsics, const bus::Pose& camera,
                         const Footprint& footprint, int min_points) {
  const std::vector<GroundPoint> points = PointsInFootprint(depth_m, intrinsics, camera, footprint);
  GroundFit fit;
  fit.points = static_cast<int>(points.size());
  if (fit.points < min_points) return fit;
  // Normal equations of z = h + gx dx + gy dy.
  cv::Matx33d normal = cv::Matx33d::zeros();
  cv::Vec3d rhs(0, 0, 0);
  for (const GroundPoint& p : points) {
    const cv::Vec3d row(1.0, p.dx_m, p.dy_m);
    normal += row * row.t();
    rhs += row * p.z_m;
  }
  cv::Vec3d plane;
  if (!cv::solve(normal, rhs, plane, cv::DECOMP_CHOLESKY)) return fit;  // points on a line
  double sum_sq = 0;
  for (const GroundPoint& p : points) {
    const double r = p.z_m - (plane[0] + plane[1] * p.dx_m + plane[2] * p.dy_m);
    sum_sq += r * r;
  }
  fit.valid = true;
  fit.height_m = plane[0];
  fit.gradient_x = plane[1];
  fit.gradient_y = plane[2];
  fit.slope_rad = std::atan(std::hypot(plane[1], plane[2]));
  fit.rms_residual_m = std::sqrt(sum_sq / fit.points);
  return fit;
}

}  // namespace swarmbox::depth
