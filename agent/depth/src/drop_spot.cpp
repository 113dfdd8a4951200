#include "swarmbox/depth/drop_spot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <tuple>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "detail/rotation.hpp"
#include "swarmbox/common/result.hpp"

namespace swarmbox::depth {
namespace {

// The binning cell [m]: ~30 pixels at 8 m (18 mm a pixel at f = 441 px), and the footprint's
// 2.6 x 1.2 m and the 0.5 m grid are whole numbers of cells, so a footprint is exactly its cells.
constexpr double kCell_m = 0.1;
// A cell is seen with this many points (its median height then says something) ...
constexpr int kMinCellPoints = 4;
// ... and a footprint is seen when this share of its cells is: SGBM leaves small holes (and a
// 0.6 m box 3 m from the nadir hides a 0.25 m strip behind it from 8 m), but a footprint partly
// out of the image (or in the matcher's blind left band) is not known to be clear: with 80 %,
// footprints at the image's edge over heaped rubble passed on SGBM's depth.
constexpr double kMinCoverage = 0.9;
// An obstacle: this many connected cells (0.06 m^2, a 25 cm stone) higher than
// max_height_above_ground_m. SGBM's mismatched blobs from 8 m are mostly one or two cells; a
// smaller stone still raises the footprint's roughness.
constexpr int kMinObstacleCells = 6;
// A footprint fails within this many cells of an obstacle cell (0.2 m): SGBM blurs and drops an
// obstacle's edge (its 5 px block is 9 cm on the ground at 8 m, and its smoothing more); with one
// cell, footprints whose margin clipped the box's corner passed.
constexpr int kObstacleReachCells = 2;

// The footprint's frame: origin the default point, axis `along` the stretcher's length; heights
// relative to ground_z_m.
struct Frame {
  double x0_m, y0_m, cos_yaw, sin_yaw, ground_z_m;
};

// A pixel's point in the footprint's frame: a along, c across [m], z above ground_z_m [m].
struct BinnedPoint {
  int cell;
  float a, c, z;
};

// A cell's points: how many, their centroid and median height (the median shrugs off SGBM's
// mismatched blobs, tens of pixels a metre off).
struct Cell {
  int n = 0;
  double a_m = 0, c_m = 0;
  double median_z_m = 0;
  bool near_obstacle = false;  // an obstacle cell within kObstacleReachCells (MarkObstacles)
};

// Square grid of cells, index (ia, ic) in [-half, half) along and across.
class CellGrid {
 public:
  explicit CellGrid(double half_extent_m)
      : half_(static_cast<int>(std::ceil(half_extent_m / kCell_m))),
        side_(2 * half_),
        cells_(static_cast<std::size_t>(side_) * static_cast<std::size_t>(side_)) {}

  // The cell holding (a, c), or -1 outside the grid.
  int IndexOf(double a_m, double c_m) const {
    const int ia = static_cast<int>(std::floor(a_m / kCell_m)), ic = static_cast<int>(std::floor(c_m / kCell_m));
    return Inside(ia, ic) ? (ia + half_) * side_ + ic + half_ : -1;
  }
  bool Inside(int ia, int ic) const { return ia >= -half_ && ia < half_ && ic >= -half_ && ic < half_; }
  const Cell& At(int ia, int ic) const { return cells_[static_cast<std::size_t>((ia + half_) * side_ + ic + half_)]; }
  void Summarize(const std::vector<BinnedPoint>& points);
  // The `quantile` (0..1) of the seen cells' median heights, or 0 with no cell seen (after
  // Summarize).
  double SeenHeightQuantile(double quantile) const;
  // Every cell's median height moved by dz_m (the ground's height found in the view: heights are
  // then above it).
  void ShiftHeights(double dz_m);
  // Each cell's near_obstacle (after Summarize): obstacle cells are seen cells higher than
  // `tall_m` above the ground in a connected region of at least kMinObstacleCells.
  void MarkObstacles(double tall_m);

 private:
  int half_, side_;
  std::vector<Cell> cells_;
};

// Counting sort of the points' heights by cell, then each cell's median.
void CellGrid::Summarize(const std::vector<BinnedPoint>& points) {
  std::vector<std::size_t> start(cells_.size() + 1, 0);
  for (const BinnedPoint& p : points) {
    Cell& cell = cells_[static_cast<std::size_t>(p.cell)];
    ++cell.n, cell.a_m += p.a, cell.c_m += p.c;
    ++start[static_cast<std::size_t>(p.cell) + 1];
  }
  for (std::size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
  std::vector<float> z(points.size());
  std::vector<std::size_t> next(start.begin(), start.end() - 1);
  for (const BinnedPoint& p : points) z[next[static_cast<std::size_t>(p.cell)]++] = p.z;
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    Cell& cell = cells_[i];
    if (cell.n == 0) continue;
    cell.a_m /= cell.n, cell.c_m /= cell.n;
    const auto first = z.begin() + static_cast<std::ptrdiff_t>(start[i]);
    const auto mid = first + cell.n / 2;
    std::nth_element(first, mid, z.begin() + static_cast<std::ptrdiff_t>(start[i + 1]));
    cell.median_z_m = *mid;
  }
}

double CellGrid::SeenHeightQuantile(double quantile) const {
  std::vector<double> heights;
  for (const Cell& cell : cells_) {
    if (cell.n >= kMinCellPoints) heights.push_back(cell.median_z_m);
  }
  if (heights.empty()) return 0.0;
  const auto k = static_cast<std::ptrdiff_t>(quantile * static_cast<double>(heights.size() - 1));
  std::nth_element(heights.begin(), heights.begin() + k, heights.end());
  return heights[static_cast<std::size_t>(k)];
}

void CellGrid::ShiftHeights(double dz_m) {
  for (Cell& cell : cells_) cell.median_z_m += dz_m;
}

void CellGrid::MarkObstacles(double tall_m) {
  cv::Mat tall(side_, side_, CV_8U, cv::Scalar(0));
  for (int row = 0; row < side_; ++row) {
    for (int col = 0; col < side_; ++col) {
      const Cell& cell = cells_[static_cast<std::size_t>(row * side_ + col)];
      if (cell.n >= kMinCellPoints && cell.median_z_m > tall_m) tall.at<std::uint8_t>(row, col) = 1;
    }
  }
  cv::Mat labels, stats, centroids;
  const int regions = cv::connectedComponentsWithStats(tall, labels, stats, centroids, 8, CV_32S);
  cv::Mat obstacle(side_, side_, CV_8U, cv::Scalar(0));
  for (int row = 0; row < side_; ++row) {
    for (int col = 0; col < side_; ++col) {
      const int label = labels.at<int>(row, col);
      if (label > 0 && label < regions && stats.at<int>(label, cv::CC_STAT_AREA) >= kMinObstacleCells) {
        obstacle.at<std::uint8_t>(row, col) = 1;
      }
    }
  }
  cv::dilate(obstacle, obstacle, cv::Mat::ones(2 * kObstacleReachCells + 1, 2 * kObstacleReachCells + 1, CV_8U));
  for (int row = 0; row < side_; ++row) {
    for (int col = 0; col < side_; ++col) {
      cells_[static_cast<std::size_t>(row * side_ + col)].near_obstacle = obstacle.at<std::uint8_t>(row, col) != 0;
    }
  }
}

// Whether world point (x0 + dx, y0 + dy, ground_z + dz) lies in a masked volume.
bool Masked(const std::vector<MaskedVolume>& masked, const Frame& f, double dx, double dy, double dz) {
  return std::ranges::any_of(masked, [&](const MaskedVolume& m) {
    return m.Contains(f.x0_m + dx, f.y0_m + dy, f.ground_z_m + dz);
  });
}

// Back-projects every pixel with depth once (as FitGroundPlane) into the footprint's frame and
// keeps those inside the grid and outside the masked volumes.
std::vector<BinnedPoint> BinPoints(const cv::Mat& depth_m, const CameraIntrinsics& k, const bus::Pose& camera,
                                   const Frame& f, const CellGrid& grid, const std::vector<MaskedVolume>& masked) {
  const std::array<double, 9> r = detail::RotationMatrix(camera.orientation_wxyz);
  const auto& c = camera.position_enu_m;
  std::vector<BinnedPoint> points;
  points.reserve(depth_m.total());
  for (int v = 0; v < depth_m.rows; ++v) {
    const auto* row = depth_m.ptr<float>(v);
    const double oy_per_z = (v + 0.5 - k.cy_px) / k.focal_px;
    for (int u = 0; u < depth_m.cols; ++u) {
      const double z = row[u];
      if (!(z > 0)) continue;
      const double ox = (u + 0.5 - k.cx_px) / k.focal_px * z, oy = oy_per_z * z;
      const double dx = c[0] + r[0] * ox + r[1] * oy + r[2] * z - f.x0_m;
      const double dy = c[1] + r[3] * ox + r[4] * oy + r[5] * z - f.y0_m;
      const double wz = c[2] + r[6] * ox + r[7] * oy + r[8] * z - f.ground_z_m;
      const double a = dx * f.cos_yaw + dy * f.sin_yaw, across = -dx * f.sin_yaw + dy * f.cos_yaw;
      const int cell = grid.IndexOf(a, across);
      if (cell >= 0 && !masked.empty() && Masked(masked, f, dx, dy, wz)) continue;
      if (cell >= 0) points.push_back({cell, static_cast<float>(a), static_cast<float>(across), static_cast<float>(wz)});
    }
  }
  return points;
}

// A candidate centre: (i, j) grid steps along and across from the default point.
struct Candidate {
  int i, j;
};

// The grid's centres within the search radius, nearest first (ties: smaller i, then smaller j).
std::vector<Candidate> Candidates(const DropSpotConfig& config) {
  const int n = static_cast<int>(std::floor(config.search_radius_m / config.grid_step_m));
  const double r_steps = config.search_radius_m / config.grid_step_m;
  std::vector<Candidate> out;
  for (int i = -n; i <= n; ++i) {
    for (int j = -n; j <= n; ++j) {
      if (i * i + j * j <= r_steps * r_steps + 1e-9) out.push_back({i, j});
    }
  }
  std::sort(out.begin(), out.end(), [](const Candidate& p, const Candidate& q) {
    return std::make_tuple(p.i * p.i + p.j * p.j, p.i, p.j) < std::make_tuple(q.i * q.i + q.j * q.j, q.i, q.j);
  });
  return out;
}

// The cells whose centres lie inside the footprint centred at offset `centre_m` ([first, last]).
std::pair<int, int> CellRange(double centre_m, double size_m) {
  return {static_cast<int>(std::ceil((centre_m - size_m / 2) / kCell_m - 0.5 - 1e-9)),
          static_cast<int>(std::floor((centre_m + size_m / 2) / kCell_m - 0.5 + 1e-9))};
}

// A footprint's seen cells: how many of its cells there are and are seen, the points in all of
// them, and the least-squares sums of the seen cells' (a - a0, c - c0, median z).
struct FootprintCells {
  int cells = 0, seen = 0, points = 0;
  bool obstacle = false;              // an obstacle cell in it or next to it
  std::pair<int, int> along, across;  // cell ranges
  cv::Matx33d normal = cv::Matx33d::zeros();
  cv::Vec3d rhs{0, 0, 0};
};

FootprintCells GatherCells(const CellGrid& grid, double a0_m, double c0_m, const DropSpotConfig& config) {
  FootprintCells s;
  s.along = CellRange(a0_m, config.length_m);
  s.across = CellRange(c0_m, config.width_m);
  for (int ia = s.along.first; ia <= s.along.second; ++ia) {
    for (int ic = s.across.first; ic <= s.across.second; ++ic) {
      ++s.cells;
      if (!grid.Inside(ia, ic)) continue;
      const Cell& cell = grid.At(ia, ic);
      s.points += cell.n;
      s.obstacle = s.obstacle || cell.near_obstacle;
      if (cell.n < kMinCellPoints) continue;
      ++s.seen;
      const cv::Vec3d row(1.0, cell.a_m - a0_m, cell.c_m - c0_m);
      s.normal += row * row.t();
      s.rhs += row * cell.median_z_m;
    }
  }
  return s;
}

// RMS of the seen cells' median heights about the plane z = h + ga (a - a0) + gc (c - c0).
double CellRoughness(const CellGrid& grid, const FootprintCells& s, double a0, double c0, const cv::Vec3d& plane) {
  double sum_sq = 0;
  for (int ia = s.along.first; ia <= s.along.second; ++ia) {
    for (int ic = s.across.first; ic <= s.across.second; ++ic) {
      if (!grid.Inside(ia, ic)) continue;
      const Cell& cell = grid.At(ia, ic);
      if (cell.n < kMinCellPoints) continue;
      const double r = cell.median_z_m - (plane[0] + plane[1] * (cell.a_m - a0) + plane[2] * (cell.c_m - c0));
      sum_sq += r * r;
    }
  }
  return std::sqrt(sum_sq / s.seen);
}

// A candidate's fit, and whether an obstacle reaches into it.
struct Evaluation {
  GroundFit fit;
  bool obstacle = false;
};

Evaluation Evaluate(const CellGrid& grid, const Frame& f, double a0, double c0, const DropSpotConfig& config) {
  const FootprintCells s = GatherCells(grid, a0, c0, config);
  Evaluation e;
  GroundFit& fit = e.fit;
  fit.points = s.points;
  if (fit.points < config.min_points || s.seen < kMinCoverage * s.cells) return e;
  cv::Vec3d plane;
  if (!cv::solve(s.normal, s.rhs, plane, cv::DECOMP_CHOLESKY)) return e;  // cells on a line
  fit.valid = true;
  fit.height_m = f.ground_z_m + plane[0];
  // z = h + ga a + gc c with a = dx cos + dy sin, c = -dx sin + dy cos.
  fit.gradient_x = plane[1] * f.cos_yaw - plane[2] * f.sin_yaw;
  fit.gradient_y = plane[1] * f.sin_yaw + plane[2] * f.cos_yaw;
  fit.slope_rad = std::atan(std::hypot(plane[1], plane[2]));
  fit.rms_residual_m = CellRoughness(grid, s, a0, c0, plane);
  e.obstacle = s.obstacle;
  return e;
}

bool Passes(const Evaluation& e, double ground_z_m, const DropSpotConfig& config) {
  const GroundFit& fit = e.fit;
  return fit.valid && fit.slope_rad <= config.max_slope_rad && fit.rms_residual_m <= config.max_roughness_m &&
         std::abs(fit.height_m - ground_z_m) <= config.max_height_above_ground_m && !e.obstacle;
}

}  // namespace

namespace {

// The candidate centre (x, y) lies in a keep-out circle.
bool KeptOut(const DropSpotConfig& config, double x_m, double y_m) {
  return std::ranges::any_of(config.keep_out,
                             [&](const KeepOut& k) { return std::hypot(x_m - k.x_m, y_m - k.y_m) < k.radius_m; });
}

// The image's points binned around the default point, with the ground's height from the view
// when config.ground_quantile asks for it (f.ground_z_m then moves to it), and the obstacle cells.
CellGrid PrepareGrid(const cv::Mat& depth_m, const CameraIntrinsics& intrinsics, const bus::Pose& camera,
                     const DropSpotConfig& config, Frame* f) {
  CellGrid grid(config.search_radius_m + std::hypot(config.length_m, config.width_m) / 2 + kCell_m);
  grid.Summarize(BinPoints(depth_m, intrinsics, camera, *f, grid, config.masked));
  if (config.ground_quantile >= 0) {  // the ground as the view shows it, not as given
    const double offset_m = grid.SeenHeightQuantile(config.ground_quantile);
    grid.ShiftHeights(-offset_m);
    f->ground_z_m += offset_m;
  }
  grid.MarkObstacles(config.max_height_above_ground_m);
  return grid;
}

}  // namespace

MaskedVolume SlungPayloadVolume(const bus::Pose& camera, const SlungPayload& payload) {
  const double swing_m = (payload.hook_below_camera_m + payload.sling_length_m) * std::sin(payload.max_tilt_rad);
  const double top_z_m = camera.position_enu_m[2];
  return {.x_m = camera.position_enu_m[0],
          .y_m = camera.position_enu_m[1],
          .radius_m = payload.hook_from_camera_m + swing_m + payload.payload_half_diagonal_m + kSlungPayloadMargin_m,
          .bottom_z_m = top_z_m - payload.hook_below_camera_m - payload.sling_length_m -
                        payload.payload_half_diagonal_m - kSlungPayloadMargin_m,
          .top_z_m = top_z_m};
}

DropSpot ChooseDropSpot(const cv::Mat& depth_m, const CameraIntrinsics& intrinsics, const bus::Pose& camera,
                        double default_x_m, double default_y_m, double yaw_rad, double ground_z_m,
                        const DropSpotConfig& config) {
  SWARMBOX_CHECK(depth_m.empty() || depth_m.type() == CV_32F);
  SWARMBOX_CHECK(config.length_m > 0 && config.width_m > 0 && config.grid_step_m > 0 && config.search_radius_m >= 0);
  SWARMBOX_CHECK(config.ground_quantile < 1.0);
  Frame f{default_x_m, default_y_m, std::cos(yaw_rad), std::sin(yaw_rad), ground_z_m};
  const CellGrid grid = PrepareGrid(depth_m, intrinsics, camera, config, &f);
  DropSpot spot;
  spot.ground_z_m = f.ground_z_m;
  spot.x_m = default_x_m;
  spot.y_m = default_y_m;
  for (const Candidate& cand : Candidates(config)) {
    const double a0 = cand.i * config.grid_step_m, c0 = cand.j * config.grid_step_m;
    const double x_m = default_x_m + a0 * f.cos_yaw - c0 * f.sin_yaw;
    const double y_m = default_y_m + a0 * f.sin_yaw + c0 * f.cos_yaw;
    if (KeptOut(config, x_m, y_m)) continue;  // never this close to the victim (or anything kept out)
    const Evaluation e = Evaluate(grid, f, a0, c0, config);
    const bool ok = Passes(e, f.ground_z_m, config);
    if (cand.i == 0 && cand.j == 0) {
      spot.at_default = e.fit;
      spot.default_ok = ok;
    }
    if (!e.fit.valid) continue;
    ++spot.candidates;
    if (!ok) continue;
    ++spot.flat;
    if (spot.found) continue;  // nearest first: the first to pass is the choice
    spot.found = true;
    spot.x_m = x_m;
    spot.y_m = y_m;
    spot.fit = e.fit;
  }
  if (!spot.found) spot.fit = spot.at_default;  // the spot stays the default point
  return spot;
}

}  // namespace swarmbox::depth
