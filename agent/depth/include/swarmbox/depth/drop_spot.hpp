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

#include <cmath>
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

// A volume whose points are dropped before binning: a vertical cylinder around (x, y) of
// radius_m from bottom_z_m to top_z_m (world ENU). The lifter's own slung payload hangs in its
// view (SlungPayloadVolume): real drones mask their payload out of their depth, or the stretcher
// under the lifter would be a raised object over its drop point. (What it hides of the ground
// stays unseen: footprints there fail as unseen, not as obstacles.)
struct MaskedVolume {
  double x_m = 0, y_m = 0;
  double radius_m = 0;
  double bottom_z_m = 0, top_z_m = 0;
  bool Contains(double px_m, double py_m, double pz_m) const {
    return pz_m >= bottom_z_m && pz_m <= top_z_m && std::hypot(px_m - x_m, py_m - y_m) <= radius_m;
  }
};

// A slung payload as the drone's camera sees it (airframe/ PayloadSpec and the stereo mount).
struct SlungPayload {
  double hook_below_camera_m = 0;      // camera's z - hook's z, the drone level [m]
  double hook_from_camera_m = 0;       // the hook's horizontal distance from the camera, level [m]
  double sling_length_m = 0;           // hook -> payload centre [m]
  double payload_half_diagonal_m = 0;  // half the payload box's diagonal (its reach from its centre) [m]
  double max_tilt_rad = 0;             // the most the drone tilts (the sling swings as far) while it holds
};
// Room around the payload's reach: the sling's stretch, the swing's overshoot past the drone's
// tilt, the camera pose's error between the exposure and its estimate.
inline constexpr double kSlungPayloadMargin_m = 0.5;

// The volume the payload can occupy under a camera at `camera` (the left optical frame): from the
// camera's height down past the hook by sling_length_m + payload_half_diagonal_m +
// kSlungPayloadMargin_m, within hook_from_camera_m + the hook's own swing with the drone's tilt +
// the sling's swing (sling_length_m sin(max_tilt_rad)) + payload_half_diagonal_m + the margin of
// the camera's nadir. x8_heavy_depth: 3.8 m around, down to 5.7 m under the camera; so the
// lifter surveys from higher than that (8 m), or the ground too is masked.
MaskedVolume SlungPayloadVolume(const bus::Pose& camera, const SlungPayload& payload);

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
  std::vector<MaskedVolume> masked{};  // points inside any of these are dropped before binning
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
