// ChooseDropSpot: where the heavy lifter sets the stretcher down near a victim (issue #23). The
// lifter holds over the default drop point (stretcher_offset_m from the victim toward home) and
// looks down with its stereo camera; this picks a flat, clear footprint for the stretcher there
// or nearby from that one depth image.
//
//   const bus::Pose camera = LeftCameraPose(body_pose, mount);
//   const DropSpot spot = ChooseDropSpot(depth_m, {f, cx, cy}, camera, default_x, default_y, yaw, ground_z, {});
//   if (spot.found) drop_xy = {spot.x_m, spot.y_m};   // else keep the default (and say so)
//
// Candidates: footprints length_m x width_m with their length along yaw_rad (the stretcher hangs
// as the lifter is yawed), centred on a grid_step_m grid aligned with the footprint around the
// default point, within search_radius_m of it. The image's points are binned into 0.1 m cells
// (~30 pixels each at 8 m); each cell keeps its centroid and its MEDIAN height (SGBM leaves
// mismatched blobs a metre off; the median shrugs them off). A candidate passes when it is:
//   seen:    at least min_points points, and at least 90 % of its cells hold 4 points or more
//            (a footprint partly out of the image, or in an occlusion shadow, is not known clear);
//   flat:    the least-squares plane through its seen cells' medians has slope_rad <= max_slope_rad;
//   smooth:  the RMS of the cells' medians about that plane <= max_roughness_m;
//   level:   the plane's height within max_height_above_ground_m of ground_z_m (the flat top of a
//            box is not the ground);
//   clear:   no obstacle within 0.2 m of it: an obstacle is 6 or more connected cells (a 25 cm
//            stone) whose medians are more than max_height_above_ground_m above ground_z_m (a box's
//            corner reaching into the footprint: the plane and the RMS barely notice a few cells;
//            0.2 m because SGBM blurs an obstacle's edge; 6 cells because its blobs are smaller).
// The default point is tried first and chosen if it passes; otherwise the passing candidate
// nearest to it (ties: smaller along-offset, then smaller across-offset: deterministic).
// So GroundFit here is the plane through cells' medians, not FitGroundPlane's pixel fit, and its
// rms_residual_m is over the cells.
//
// What SGBM gives at the 8 m survey height (OAK-D Pro, f = 441 px, B = 7.5 cm: the ground is at a
// disparity of 4.1 px), measured on flat ground with rubble's texture in
// tests/agent/depth/drop_spot_test.cpp: the plane's height 0.20-0.29 m too LOW (a bias of ~1/8 px),
// cell RMS 0.07-0.22 m (median 0.084), and in some scenes a quarter of the footprints corrupted
// (apparent slopes of 6-10 deg, raised patches). Over 28 seeded scenes: a box on the default
// point -> the nearest clear footprint 27 times (once a margin's corner clipped the box; the
// stretcher itself always clear); flat ground -> the default kept 23 times (the false rejects send
// the stretcher to the nearest passing spot: the safe side); rubble heaped everywhere -> no spot 28
// times. A lower survey height would do much better (the depth error grows with the range squared).
//
// Cost: the image is back-projected once (each pixel with depth, as FitGroundPlane does) and
// counting-sorted into the cells; a candidate then visits its ~310 cells. 640 x 400 depth, ~450
// candidates (~230 in view): 9-17 ms on one core of the (loaded) dev machine.
// Pure: no I/O, no clock.
#pragma once

#include <numbers>
#include <vector>

#include <opencv2/core.hpp>

#include "swarmbox/bus/messages.hpp"
#include "swarmbox/depth/ground_plane.hpp"

namespace swarmbox::depth {

// A circle no candidate's centre may fall in (the victim: the stretcher is set down beside them,
// not on them).
struct KeepOut {
  double x_m = 0, y_m = 0;
  double radius_m = 0;
};

struct DropSpotConfig {
  // The stretcher is 2.0 x 0.6 m; 0.3 m margin each side for the release's position error (the
  // slung load still swings a little when let go) and for the rescuers' footing beside it.
  double length_m = 2.6;
  double width_m = 1.2;
  // A stretcher with a person on it must not slide or tip: 5 deg keeps the downhill pull below
  // 9 % of the weight, well under the friction of a litter on concrete or soil.
  double max_slope_rad = 5.0 * std::numbers::pi / 180.0;
  // RMS of the cells' median heights about the plane [m]: SGBM's at the 8 m survey height on flat
  // textured ground is 0.084 m (median over footprints; 0.11 at the 90th percentile, 0.12-0.15 in
  // a few); a heap's flank or a box edge in the footprint raises it well above (0.15-0.5 m measured).
  double max_roughness_m = 0.15;
  // The plane's height vs ground_z_m (both ways), and an obstacle's cells above it [m]: the release
  // height is computed from the ground's height, and the top of a box is not the ground. SGBM reads
  // flat ground 0.20-0.29 m low from 8 m and the 0.6 m box's top at 0.42-0.66 m: between them.
  double max_height_above_ground_m = 0.35;
  double search_radius_m = 6.0;  // candidate centres within this of the default point
  double grid_step_m = 0.5;      // candidate centres' spacing, along and across the footprint
  int min_points = 50;           // pixels in a footprint for a fit
  // The ground's height from the view itself, this quantile of the seen cells' median heights
  // (negative: ground_z_m as given). A drone knows its own height only as well as its estimate
  // (baro and GPS: tenths of a metre), and SGBM reads flat ground 0.2-0.3 m low from 8 m (above):
  // both shift every cell alike and cancel against the ground seen around the point. 0.3: the
  // ground is taken to be the lowest surface covering at least 30 % of the view (a rubble field
  // over most of the view then has its lowest parts as "ground", and its slopes and roughness
  // still fail). The candidates' checks are then relative to that (DropSpot::ground_z_m).
  double ground_quantile = -1.0;
  std::vector<KeepOut> keep_out; // candidate centres inside any of these are skipped
};

struct DropSpot {
  bool found = false;          // a candidate passed every test
  double x_m = 0, y_m = 0;     // the chosen footprint's centre (world ENU); the default if not found
  GroundFit fit;               // at the chosen spot (the cells' plane, see above); at_default if not found
  GroundFit at_default;        // the fit at the default point (valid = false if not seen)
  bool default_ok = false;     // the default point itself passed
  int candidates = 0;          // footprints evaluated with a valid fit
  int flat = 0;                // of them, passing
  double ground_z_m = 0;       // the ground's height the checks used (ground_z_m, or the view's)
};

// `depth_m`: CV_32F along the optical axis, 0 = no depth (StereoMatcher's, or the renderer's
// truth); `camera`: the left camera's optical frame (LeftCameraPose); yaw_rad: direction of the
// stretcher's length, from east towards north; ground_z_m: the ground's height the lifter flies by.
DropSpot ChooseDropSpot(const cv::Mat& depth_m, const CameraIntrinsics& intrinsics, const bus::Pose& camera,
                        double default_x_m, double default_y_m, double yaw_rad, double ground_z_m,
                        const DropSpotConfig& config);

}  // namespace swarmbox::depth
