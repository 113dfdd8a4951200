// DepthSurface: the heights of the surfaces one depth frame sees, on a horizontal grid, for asking
// "how high is the surface near (x, y)?" (issue #23: "geolocation uses range from depth instead of
// assuming flat ground"; agent/app PerceptionHost re-intersects a detection's pixel ray with the
// surface's height there: swarm::VictimPerception::ProcessFrame's GroundHeightSource).
//
//   const DepthSurface surface(f.frame.depth_m, f.intrinsics, f.camera_pose, {});
//   if (const std::optional<double> z = surface.HeightNear(x, y, 0.5)) ...  // else: not seen
//
// Each pixel with depth in (0, max_range_m] is back-projected as FitGroundPlane does (the pixel's
// centre, the left camera's optical frame, then the world by `camera`) and binned into cell_m
// cells of the world's x-y plane over the points' bounding box; each cell with min_cell_points or
// more keeps the MEDIAN of their heights (SGBM leaves mismatched blobs tens of pixels large a metre
// off: a cell's median shrugs off most of them). HeightNear is the median of the seen cells'
// medians whose centres lie within radius_m of (x, y), nullopt with fewer than min_cells of them
// (not seen: outside the view, beyond the range, in SGBM's blind left band or a hole).
// The median over cells (not a mean) is the surface that covers most of the circle: at a slab's
// edge it is the slab's height or the ground's, never a height in between that no surface has.
//
// Measured on rendered scenes (tests/agent/depth/depth_surface_test.cpp: rubble's texture in sun,
// 640 x 400, f = 441 px, B = 7.5 cm, a level body 8 m over flat ground with a 3 x 3 m box 3 m tall
// beside the nadir; HeightNear within 0.5 m): on the true depth the box's top 3.000 m and the
// ground 0.000 m; on StereoSGBM's depth (seeds 3-5) the top 3.19 m (5 m from the camera) and the
// ground -0.18 .. -0.31 m (8 m: SGBM's bias there, as ChooseDropSpot measures it); from 20 m
// nothing (beyond the range).
// Cost: one pass over the image and a counting sort into the cells (~230,000 points, ~1,250 seen
// cells): 8-16 ms for a 640 x 400 frame on one core of the loaded dev machine; HeightNear visits
// the cells of the circle's bounding square. Pure: no I/O, no clock.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "swarmbox/bus/messages.hpp"
#include "swarmbox/depth/ground_plane.hpp"
#include "swarmbox/depth/stereo_matcher.hpp"

namespace swarmbox::depth {

struct DepthSurfaceConfig {
  // The grid's cell [m]: ~30 pixels at 8 m and ~8 at 15 m (f = 441 px); a person lying down covers
  // a few cells, so a height near them is theirs or the surface they lie on.
  double cell_m = 0.25;
  double max_range_m = kTrustedDepthRangeM;  // depth beyond this is ignored [m] (stereo_matcher.hpp)
  // A cell's median counts with this many points (as ChooseDropSpot's and ClearanceBelow's).
  int min_cell_points = 4;
  // HeightNear answers with at least this many seen cells in its circle: one or two cells may be a
  // mismatched blob of SGBM's (mostly 1-2 cells of 0.1 m from 8 m; agent/depth drop_spot.hpp).
  int min_cells = 3;
};

class DepthSurface {
 public:
  // `depth_m`: CV_32F along the optical axis, 0 = no depth (StereoMatcher's, or the renderer's
  // truth); `camera`: the left camera's optical frame (LeftCameraPose).
  DepthSurface(const cv::Mat& depth_m, const CameraIntrinsics& intrinsics, const bus::Pose& camera,
               const DepthSurfaceConfig& config);

  // The median of the seen cells' median heights (world z, ENU [m]) whose centres are within
  // radius_m of (x_m, y_m); nullopt with fewer than min_cells such cells.
  std::optional<double> HeightNear(double x_m, double y_m, double radius_m) const;

  int points() const { return points_; }        // pixels within the range
  int seen_cells() const { return seen_cells_; }  // cells with min_cell_points or more

 private:
  DepthSurfaceConfig config_;
  double origin_x_m_ = 0, origin_y_m_ = 0;  // the grid's corner (cell (0, 0)'s lower-left)
  int cols_ = 0, rows_ = 0;
  std::vector<float> median_z_m_;  // row-major, NaN where not seen
  int points_ = 0;
  int seen_cells_ = 0;
};

}  // namespace swarmbox::depth
