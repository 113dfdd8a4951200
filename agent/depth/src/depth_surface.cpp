#include "swarmbox/depth/depth_surface.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

#include "detail/rotation.hpp"
#include "swarmbox/common/result.hpp"

namespace swarmbox::depth {
namespace {

struct WorldPoint {
  double x_m, y_m;
  float z_m;
};

// Every pixel with depth in (0, max_range_m], back-projected into the world.
std::vector<WorldPoint> BackProject(const cv::Mat& depth_m, const CameraIntrinsics& k, const bus::Pose& camera,
                                    double max_range_m) {
  const std::array<double, 9> r = detail::RotationMatrix(camera.orientation_wxyz);
  const auto& c = camera.position_enu_m;
  std::vector<WorldPoint> points;
  for (int v = 0; v < depth_m.rows; ++v) {
    const auto* row = depth_m.ptr<float>(v);
    const double oy_per_z = (v + 0.5 - k.cy_px) / k.focal_px;
    for (int u = 0; u < depth_m.cols; ++u) {
      const double z = row[u];
      if (!(z > 0) || z > max_range_m) continue;
      const double ox = (u + 0.5 - k.cx_px) / k.focal_px * z, oy = oy_per_z * z;
      points.push_back({c[0] + r[0] * ox + r[1] * oy + r[2] * z, c[1] + r[3] * ox + r[4] * oy + r[5] * z,
                        static_cast<float>(c[2] + r[6] * ox + r[7] * oy + r[8] * z)});
    }
  }
  return points;
}

// The grid over the points' bounding box: its corner and size in cells. The points are within
// max_range_m of the camera, so at most 2 max_range_m / cell_m cells a side (120 at the defaults).
struct Grid {
  double origin_x_m, origin_y_m;
  int cols, rows;
};
Grid BoundingGrid(const std::vector<WorldPoint>& points, double cell_m) {
  double min_x = points[0].x_m, min_y = points[0].y_m, max_x = min_x, max_y = min_y;
  for (const WorldPoint& p : points) {
    min_x = std::min(min_x, p.x_m), min_y = std::min(min_y, p.y_m);
    max_x = std::max(max_x, p.x_m), max_y = std::max(max_y, p.y_m);
  }
  return {min_x, min_y, static_cast<int>(std::floor((max_x - min_x) / cell_m)) + 1,
          static_cast<int>(std::floor((max_y - min_y) / cell_m)) + 1};
}

}  // namespace

DepthSurface::DepthSurface(const cv::Mat& depth_m, const CameraIntrinsics& intrinsics, const bus::Pose& camera,
                           const DepthSurfaceConfig& config)
    : config_(config) {
  SWARMBOX_CHECK(depth_m.empty() || depth_m.type() == CV_32F);
  SWARMBOX_CHECK(config.cell_m > 0 && config.max_range_m > 0 && config.min_cell_points >= 1 && config.min_cells >= 1);
  const std::vector<WorldPoint> points = BackProject(depth_m, intrinsics, camera, config.max_range_m);
  points_ = static_cast<int>(points.size());
  if (points.empty()) return;
  const Grid grid = BoundingGrid(points, config.cell_m);
  origin_x_m_ = grid.origin_x_m, origin_y_m_ = grid.origin_y_m, cols_ = grid.cols, rows_ = grid.rows;
  const auto cells = static_cast<std::size_t>(cols_) * static_cast<std::size_t>(rows_);
  auto cell_of = [&](const WorldPoint& p) {
    const int col = std::min(static_cast<int>((p.x_m - origin_x_m_) / config.cell_m), cols_ - 1);
    const int row = std::min(static_cast<int>((p.y_m - origin_y_m_) / config.cell_m), rows_ - 1);
    return static_cast<std::size_t>(row) * static_cast<std::size_t>(cols_) + static_cast<std::size_t>(col);
  };
  // Counting sort of the heights by cell, then each cell's median.
  std::vector<std::size_t> start(cells + 1, 0);
  for (const WorldPoint& p : points) ++start[cell_of(p) + 1];
  for (std::size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
  std::vector<float> z(points.size());
  std::vector<std::size_t> next(start.begin(), start.end() - 1);
  for (const WorldPoint& p : points) z[next[cell_of(p)]++] = p.z_m;
  median_z_m_.assign(cells, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t i = 0; i < cells; ++i) {
    const auto n = static_cast<std::ptrdiff_t>(start[i + 1] - start[i]);
    if (n < config.min_cell_points) continue;
    const auto first = z.begin() + static_cast<std::ptrdiff_t>(start[i]);
    std::nth_element(first, first + n / 2, first + n);
    median_z_m_[i] = first[n / 2];
    ++seen_cells_;
  }
}

std::optional<double> DepthSurface::HeightNear(double x_m, double y_m, double radius_m) const {
  if (seen_cells_ == 0) return std::nullopt;
  const double cell = config_.cell_m;
  // The cells whose centres can be within the radius (clamped to the grid).
  const int col_first = std::max(0, static_cast<int>(std::ceil((x_m - radius_m - origin_x_m_) / cell - 0.5)));
  const int col_last = std::min(cols_ - 1, static_cast<int>(std::floor((x_m + radius_m - origin_x_m_) / cell - 0.5)));
  const int row_first = std::max(0, static_cast<int>(std::ceil((y_m - radius_m - origin_y_m_) / cell - 0.5)));
  const int row_last = std::min(rows_ - 1, static_cast<int>(std::floor((y_m + radius_m - origin_y_m_) / cell - 0.5)));
  std::vector<float> heights;
  for (int row = row_first; row <= row_last; ++row) {
    const double dy = origin_y_m_ + (row + 0.5) * cell - y_m;
    for (int col = col_first; col <= col_last; ++col) {
      const double dx = origin_x_m_ + (col + 0.5) * cell - x_m;
      if (dx * dx + dy * dy > radius_m * radius_m) continue;
      const float h = median_z_m_[static_cast<std::size_t>(row) * static_cast<std::size_t>(cols_) +
                                  static_cast<std::size_t>(col)];
      if (!std::isnan(h)) heights.push_back(h);
    }
  }
  if (std::ssize(heights) < config_.min_cells) return std::nullopt;
  const auto mid = heights.begin() + std::ssize(heights) / 2;
  std::nth_element(heights.begin(), mid, heights.end());
  return static_cast<double>(*mid);
}

}  // namespace swarmbox::depth
