// ClearanceBelow: how high the highest surface under and around a scout is, from one depth frame
// of its downward stereo camera (issue #23: "scouts use [depth] to hold a safe height over rubble
// and trees"). The scout's mission (agent/swarm ScoutBehaviour, ScoutConfig::min_clearance_m)
// raises its cruise altitude to top_z_m + min_clearance_m when that is above its search altitude.
//
//   const bus::Pose camera = LeftCameraPose(body_pose, mount);
//   const Clearance c = ClearanceBelow(depth_m, {f, cx, cy}, camera, {});
//   if (c.valid) in.obstacle_top_z_m = c.top_z_m;   // else: nothing within range, no depth
//
// Each pixel with depth in (0, max_range_m] is back-projected as FitGroundPlane does (the pixel's
// centre, the left camera's optical frame, then the world by `camera`); those whose horizontal
// distance from the camera's nadir is at most radius_m are binned into 0.1 m cells (as
// ChooseDropSpot does), each cell with 4 or more points keeps the MEDIAN of their heights (SGBM
// leaves mismatched blobs tens of pixels large a metre off; a cell's median shrugs off most of
// them). The top is the top_cells-th highest cell median: the highest height that a patch of at
// least top_cells cells (0.25 m^2 by default, a crown's tuft or a slab's corner) reaches, not a
// single pixel or cell. The camera looks straight down (78 x 61 deg, the 61 deg along the body's
// x), so "around" is the part of the radius in the image: ahead of the nadir it sees
// tan(30.5 deg) = 0.59 x the range; a 6 m obstacle is seen ~3.5 m before the scout is over it.
// Not seen: anything thinner than ~0.5 m (poles, wires, bare branches), anything in SGBM's blind
// left band, anything beyond max_range_m (the projector's 15 m, and SGBM's error beyond it).
//
// Measured on rendered scenes (tests/agent/depth/clearance_test.cpp: rubble's texture in sun, the
// renderer's true depth and StereoSGBM of its pair, 640 x 400, f = 441 px, B = 7.5 cm, the body
// level, seeds 3-5), top_z_m's error (SGBM's always too HIGH: clearance underestimated, the safe
// side; the true depth's within 2 mm everywhere):
//   flat ground from  8 m: +0.06 .. +0.18 m          (SGBM's median depth error at 8 m: 0.28 m)
//   flat ground from 12 m: +1.16 m (every seed)      (at 12 m: median 0.77, p90 0.98 m)
//   a 3 x 3 m box 6 m tall under the camera at 12 m: top 6.44 m, clearance 5.51 m for a true 5.95
//   a 0.3 m pole 7 m tall beside a 1 x 1 m crown 4 m tall (12 m): top 4.00 (truth), 4.18 (SGBM)
//   flat ground from 20 m (beyond the range): invalid (0 points true, 0-20 with SGBM)
// The 12 m figure is the upper tail of the ground's error (the top is an upper order statistic;
// SGBM's sub-pixel steps of 1/16 px are 0.24 m at 12 m): clearances read 1.2 m short there.
// Cost: one pass over the image, a counting sort into ~10,000 cells: 5-18 ms for a 640 x 400 frame
// with depth (0.5-1 ms with none in range) on one core of the loaded dev machine.
// Pure: no I/O, no clock.
#pragma once

#include <opencv2/core.hpp>

#include "swarmbox/bus/messages.hpp"
#include "swarmbox/depth/ground_plane.hpp"
#include "swarmbox/depth/stereo_matcher.hpp"

namespace swarmbox::depth {

struct ClearanceConfig {
  // Horizontal distance from the camera's nadir [m]: the x500 (0.62 m across) plus its position
  // error and the flocking's sideways motion, and 1 s of cruise (5 m/s) ahead: 5 m.
  double radius_m = 5.0;
  double max_range_m = kTrustedDepthRangeM;  // depth beyond this is ignored [m] (stereo_matcher.hpp)
  // Pixels inside the radius and the range for a valid answer: ~0.6 x 0.6 m seen at 15 m
  // (3.4 cm a pixel); fewer is SGBM's scattered false matches on ground beyond the range.
  int min_points = 400;
  // The top is the height reached by this many cells (0.1 m each, 0.25 m^2): SGBM's mismatched
  // blobs cover 1-2 cells from 8 m (agent/depth drop_spot.hpp); a tree's crown is metres across.
  int top_cells = 25;
};

struct Clearance {
  bool valid = false;      // at least min_points points and top_cells seen cells
  double top_z_m = 0;      // the highest surface's world z (ENU) [m]
  double clearance_m = 0;  // camera height - top_z_m [m]
  int points = 0;          // pixels within radius_m and max_range_m
};

// `depth_m`: CV_32F along the optical axis, 0 = no depth (StereoMatcher's, or the renderer's
// truth); `camera`: the left camera's optical frame (LeftCameraPose).
Clearance ClearanceBelow(const cv::Mat& depth_m, const CameraIntrinsics& intrinsics, const bus::Pose& camera,
                         const ClearanceConfig& config);

}  // namespace swarmbox::depth
