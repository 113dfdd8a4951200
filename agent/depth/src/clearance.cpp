#include "swarmbox/depth/clearance.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <vector>

#include "detail/rotation.hpp"
#include "swarmbox/common/result.hpp"

namespace swarmbox::depth {
namespace {

// The binning cell [m], as ChooseDropSpot's: ~27 pixels at 12 m, ~9 at 15 m (f = 441 px).
constexpr double kCell_m = 0.1;
// A cell's median height counts with this many points (as ChooseDropSpot's).
constexpr int kMinCellPoints = 4;

// A back-projected point: its cell (row-major over the square grid around the nadir) and height.
struct CellPoint {
  int cell;
  float z_m;
};

// The points within the radius and the range, binned around the camera's nadir (grid side `side`).
std::vector<CellPoint> BinPoints(const cv::Mat& depth_m, const CameraIntrinsics& k, const bus::Pose& camera,
                                 const ClearanceConfig& config, int half) {
  const std::array<double, 9> r = detail::RotationMatrix(camera.orientation_wxyz);
  const auto& c = camera.position_enu_m;
  const double range = config.max_range_m, radius_sq = config.radius_m * config.radius_m;
  const int side = 2 * half;
  std::vector<CellPoint> points;
  for (int v = 0; v < depth_m.rows; ++v) {
    const auto* row = depth_m.ptr<float>(v);
    const double oy_per_z = (v + 0.5 - k.cy_px) / k.focal_px;
    for (int u = 0; u < depth_m.cols; ++u) {
      const double z = row[u];
      if (!(z > 0) || z > range) continue;
      const double ox = (u + 0.5 - k.cx_px) / k.focal_px * z, oy = oy_per_z * z;
      const double dx = r[0] * ox + r[1] * oy + r[2] * z, dy = r[3] * ox + r[4] * oy + r[5] * z;
      if (dx * dx + dy * dy > radius_sq) continue;
      const int ix = std::clamp(static_cast<int>(std::floor(dx / kCell_m)) + half, 0, side - 1);
      const int iy = std::clamp(static_cast<int>(std::floor(dy / kCell_m)) + half, 0, side - 1);
      points.push_back({iy * side + ix, static_cast<float>(c[2] + r[6] * ox + r[7] * oy + r[8] * z)});
    }
  }
  return points;
}

// The median height of every cell with kMinCellPoints points or more (counting sort by cell).
std::vector<double> CellMedians(const std::vector<CellPoint>& points, std::size_t cells) {
  std::vector<std::size_t> start(cells + 1, 0);
  for (const CellPoint& p : points) ++start[static_cast<std::size_t>(p.cell) + 1];
  for (std::size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
  std::vector<float> z(points.size());
  std::vector<std::size_t> next(start.begin(), start.end() - 1);
  for (const CellPoint& p : points) z[next[static_cast<std::size_t>(p.cell)]++] = p.z_m;
  std::vector<double> medians;
  for (std::size_t i = 0; i < cells; ++i) {
    const auto n = static_cast<std::ptrdiff_t>(start[i + 1] - start[i]);
    if (n < kMinCellPoints) continue;
    const auto first = z.begin() + static_cast<std::ptrdiff_t>(start[i]);
    std::nth_element(first, first + n / 2, first + n);
    medians.push_back(first[n / 2]);
  }
  return medians;
}

}  // namespace

Clearance ClearanceBelow(const cv::Mat& depth_m, const CameraIntrinsics& intrinsics, const bus::Pose& camera,
                         const ClearanceConfig& config) {
  SWARMBOX_CHECK(depth_m.empty() || depth_m.type() == CV_32F);
  SWARMBOX_CHECK(config.radius_m > 0 && config.max_range_m > 0 && config.top_cells >= 1);
  const int half = static_cast<int>(std::ceil(config.radius_m / kCell_m)) + 1;
  const std::vector<CellPoint> points = BinPoints(depth_m, intrinsics, camera, config, half);
  Clearance out;
  out.points = static_cast<int>(points.size());
  std::vector<double> medians = CellMedians(points, static_cast<std::size_t>(4 * half * half));
  if (out.points < config.min_points || std::ssize(medians) < config.top_cells) return out;
  const auto kth = medians.begin() + (config.top_cells - 1);
  std::nth_element(medians.begin(), kth, medians.end(), std::greater<>());
  out.valid = true;
  out.top_z_m = *kth;
  out.clearance_m = camera.position_enu_m[2] - out.top_z_m;
  return out;
}

}  // namespace swarmbox::depth
