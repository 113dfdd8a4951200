#include "swarmbox/swarm/search_pattern.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {

Rect AsRect(const raft::Sector& s) { return {s.x_min_m, s.y_min_m, s.x_max_m, s.y_max_m}; }

CameraFootprint GroundFootprint(double altitude_m, double hfov_rad, int width_px, int height_px) {
  SWARMBOX_CHECK(altitude_m > 0 && hfov_rad > 0 && hfov_rad < std::numbers::pi);
  SWARMBOX_CHECK(width_px > 0 && height_px > 0);
  const double half_w = std::tan(hfov_rad / 2);  // = (width/2) / f
  const double half_h = half_w * static_cast<double>(height_px) / static_cast<double>(width_px);
  return {2 * altitude_m * half_w, 2 * altitude_m * half_h};
}

double SweepSpacing(const CameraFootprint& footprint, double overlap) {
  SWARMBOX_CHECK(overlap >= 0 && overlap < 1);
  return footprint.across_m * (1 - overlap);
}

std::vector<raft::Sector> PartitionArea(const Rect& area, std::span<const std::string> drones) {
  SWARMBOX_CHECK(area.width_m() > 0 && area.height_m() > 0);
  std::vector<raft::Sector> out;
  const auto n = static_cast<double>(drones.size());
  const bool split_x = area.width_m() >= area.height_m();  // strips across the longer side
  for (std::size_t i = 0; i < drones.size(); ++i) {
    const double a = static_cast<double>(i) / n;
    const double b = static_cast<double>(i + 1) / n;
    raft::Sector s;
    s.drone = drones[i];
    if (split_x) {
      s.x_min_m = area.x_min_m + a * area.width_m();
      s.x_max_m = i + 1 == drones.size() ? area.x_max_m : area.x_min_m + b * area.width_m();
      s.y_min_m = area.y_min_m;
      s.y_max_m = area.y_max_m;
    } else {
      s.y_min_m = area.y_min_m + a * area.height_m();
      s.y_max_m = i + 1 == drones.size() ? area.y_max_m : area.y_min_m + b * area.height_m();
      s.x_min_m = area.x_min_m;
      s.x_max_m = area.x_max_m;
    }
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<Waypoint> LawnmowerWaypoints(const Rect& sector, double spacing_m, double altitude_m,
                                         const CameraFootprint& footprint,
                                         const Eigen::Vector2d& start_xy_m) {
  SWARMBOX_CHECK(spacing_m > 0 && sector.width_m() > 0 && sector.height_m() > 0);
  // Lanes run along `u` (the longer side), stacked along `w`.
  const bool lanes_along_x = sector.width_m() >= sector.height_m();
  const double u_min = lanes_along_x ? sector.x_min_m : sector.y_min_m;
  const double u_max = lanes_along_x ? sector.x_max_m : sector.y_max_m;
  const double w_min = lanes_along_x ? sector.y_min_m : sector.x_min_m;
  const double w_max = lanes_along_x ? sector.y_max_m : sector.x_max_m;
  const double lane_span = w_max - w_min;
  const int lanes = std::max(1, static_cast<int>(std::ceil(lane_span / spacing_m - 1e-9)));
  const double step = lane_span / lanes;
  const double inset = std::min(footprint.along_m / 2, (u_max - u_min) / 2);
  const double su = lanes_along_x ? start_xy_m.x() : start_xy_m.y();
  const double sw = lanes_along_x ? start_xy_m.y() : start_xy_m.x();
  const bool w_up = std::abs(sw - w_min) <= std::abs(sw - w_max);
  bool u_forward = std::abs(su - u_min) <= std::abs(su - u_max);
  std::vector<Waypoint> out;
  out.reserve(static_cast<std::size_t>(2 * lanes));
  for (int i = 0; i < lanes; ++i) {
    const int lane = w_up ? i : lanes - 1 - i;
    const double w = w_min + (lane + 0.5) * step;
    const double u0 = u_forward ? u_min + inset : u_max - inset;
    const double u1 = u_forward ? u_max - inset : u_min + inset;
    const double yaw = lanes_along_x ? (u_forward ? 0.0 : std::numbers::pi)
                                     : (u_forward ? std::numbers::pi / 2 : -std::numbers::pi / 2);
    for (double u : {u0, u1}) {
      Waypoint p;
      p.position_m = lanes_along_x ? Eigen::Vector3d(u, w, altitude_m) : Eigen::Vector3d(w, u, altitude_m);
      p.yaw_rad = yaw;
      out.push_back(p);
    }
    u_forward = !u_forward;
  }
  return out;
}

std::vector<Waypoint> OrbitWaypoints(const Eigen::Vector2d& center_xy_m, double radius_m,
                                     double altitude_m, int count, double phase_rad) {
  SWARMBOX_CHECK(count >= 3 && radius_m > 0);
  std::vector<Waypoint> out;
  out.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const double a = phase_rad + 2 * std::numbers::pi * i / count;
    Waypoint p;
    p.position_m = Eigen::Vector3d(center_xy_m.x() + radius_m * std::cos(a),
                                   center_xy_m.y() + radius_m * std::sin(a), altitude_m);
    p.yaw_rad = std::remainder(a + std::numbers::pi, 2 * std::numbers::pi);
    out.push_back(p);
  }
  return out;
}

std::size_t NextOrbitWaypoint(std::span<const Waypoint> orbit, const Eigen::Vector2d& center_xy_m,
                              const Eigen::Vector2d& position_xy_m, double lead_rad) {
  SWARMBOX_CHECK(!orbit.empty());
  const Eigen::Vector2d d = position_xy_m - center_xy_m;
  const double own = std::atan2(d.y(), d.x());
  std::size_t best = 0;
  double best_ahead = 1e9;
  for (std::size_t i = 0; i < orbit.size(); ++i) {
    const Eigen::Vector2d q = orbit[i].position_m.head<2>() - center_xy_m;
    double ahead = std::atan2(q.y(), q.x()) - own;  // counter-clockwise angle from us to it
    while (ahead < 0) ahead += 2 * std::numbers::pi;
    while (ahead >= 2 * std::numbers::pi) ahead -= 2 * std::numbers::pi;
    if (ahead >= lead_rad && ahead < best_ahead) {
      best_ahead = ahead;
      best = i;
    }
  }
  return best;
}

}  // namespace swarmbox::swarm
