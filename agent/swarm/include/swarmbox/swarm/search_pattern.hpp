// Search geometry for the SAR mission: the camera footprint on the ground, the partition of a
// search area into per-drone sectors, lawnmower sweeps and orbit waypoints. Pure functions.
//
//   const CameraFootprint fp = GroundFootprint(30.0, 1.2, 320, 240);   // 41.0 m x 30.7 m
//   const double lane_m = SweepSpacing(fp, 0.2);                        // 20% side overlap
//   std::vector<raft::Sector> sectors = PartitionArea(area, {"scout_1", "scout_2", "scout_3"});
//   std::vector<Waypoint> path = LawnmowerWaypoints(AsRect(sectors[0]), lane_m, 30.0, fp, home_xy);
//
// Frames: world ENU [m]; yaw is the heading of body x, counter-clockwise from east [rad]. The
// downward camera's image width lies along body y, so a drone flying a lane nose-first sweeps a
// swath as wide as the footprint's across-track extent.
#pragma once

#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "swarmbox/raft/mission_command.hpp"

namespace swarmbox::swarm {

// An axis-aligned rectangle in world ENU [m].
struct Rect {
  double x_min_m = 0, y_min_m = 0, x_max_m = 0, y_max_m = 0;
  double width_m() const { return x_max_m - x_min_m; }   // along x (east)
  double height_m() const { return y_max_m - y_min_m; }  // along y (north)
  Eigen::Vector2d center_m() const { return {(x_min_m + x_max_m) / 2, (y_min_m + y_max_m) / 2}; }
  bool Contains(const Eigen::Vector2d& p) const {
    return p.x() >= x_min_m && p.x() <= x_max_m && p.y() >= y_min_m && p.y() <= y_max_m;
  }
};
Rect AsRect(const raft::Sector& sector);

// Ground footprint of a nadir pinhole camera over flat ground [m].
struct CameraFootprint {
  double across_m = 0;  // along the image width (body y): the swath of a lane
  double along_m = 0;   // along the image height (body x)
};
// altitude_m > 0 above the ground, hfov_rad in (0, pi). Aborts otherwise (a configuration bug).
CameraFootprint GroundFootprint(double altitude_m, double hfov_rad, int width_px, int height_px);
// Lane spacing that gives `overlap` in [0, 1) side overlap between neighbouring swaths [m].
double SweepSpacing(const CameraFootprint& footprint, double overlap);

// The grid PartitionArea cuts `area` into for `n` sectors: `bands` bands of equal width across
// the shorter side (floor(sqrt(n * short / long)), at least 1), each cut along the longer side
// into cells[b] cells of equal length (n / bands, the first n % bands bands one more). The cells
// are then close to square (a lane of the sweep runs along a cell's longer side, so square cells
// waste least at the turns), and fewer than 4 sectors per unit of aspect ratio stay strips: the
// shipped 3-scout trials keep their strips. 100 sectors on a square: 10 x 10; 40: 6 bands of
// 7,7,7,7,6,6.
struct PartitionGrid {
  bool bands_along_y = true;       // the longer side is x: bands are rows of cells along x
  std::vector<std::size_t> cells;  // cells per band, band 0 at the low end of the shorter side
};
PartitionGrid PartitionGridFor(const Rect& area, std::size_t n);

// Splits `area` into the cells of PartitionGridFor(area, drones.size()), assigned in the order
// given: band by band from the low end of the shorter side, cells from the low end of the longer
// side within a band. Callers pass a sorted roster (or one ordered by PartitionOrder) so that
// every drone computes the same plan. Empty `drones` gives no sectors.
std::vector<raft::Sector> PartitionArea(const Rect& area, std::span<const std::string> drones);

// The order of `drones` (positions_m[i] is where drones[i] is, world ENU [m]) that hands each
// drone the cell of PartitionArea matching its place in the swarm: sorted across the bands by the
// shorter-side coordinate, cut into bands of PartitionGridFor's sizes, each band sorted along the
// longer side (ties by name: the same order whoever computes it). Drones on a take-off grid then
// fly to their cells without crossing each other's paths (the map keeps their left/right and
// front/back order). Returns indices into `drones`.
std::vector<std::size_t> PartitionOrder(const Rect& area, std::span<const std::string> drones,
                                        std::span<const Eigen::Vector2d> positions_m);

struct Waypoint {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // world ENU [m]
  double yaw_rad = 0.0;
};

// Boustrophedon (lawnmower) sweep of `sector` at `altitude_m`: lanes parallel to the sector's
// longer side, at most `spacing_m` apart and half a spacing in from the sides, so the swaths cover
// the sector; each lane ends half a footprint (along-track) in from the sector's edge. The sweep
// starts at the corner nearest `start_xy_m`. Yaw follows the lane (nose first). spacing_m > 0.
std::vector<Waypoint> LawnmowerWaypoints(const Rect& sector, double spacing_m, double altitude_m,
                                         const CameraFootprint& footprint,
                                         const Eigen::Vector2d& start_xy_m);

// `count` >= 3 points on a circle of `radius_m` around `center_xy_m` at `altitude_m`,
// counter-clockwise from angle `phase_rad` (ENU, from east), yaw facing the centre (so the
// downward camera's forward edge sees the target).
std::vector<Waypoint> OrbitWaypoints(const Eigen::Vector2d& center_xy_m, double radius_m,
                                     double altitude_m, int count, double phase_rad);

// The index of the orbit waypoint to fly to from `position_xy_m`: the first one at least
// `lead_rad` ahead (counter-clockwise) of the drone's angle around the centre, so that following
// it circles the target.
std::size_t NextOrbitWaypoint(std::span<const Waypoint> orbit, const Eigen::Vector2d& center_xy_m,
                              const Eigen::Vector2d& position_xy_m, double lead_rad);

}  // namespace swarmbox::swarm
