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

PartitionGrid PartitionGridFor(const Rect& area, std::size_t n) {
  SWARMBOX_CHECK(area.width_m() > 0 && area.height_m() > 0);
  PartitionGrid g;
  g.bands_along_y = area.width_m() >= area.height_m();
  if (n == 0) return g;
  const double long_m = std::max(area.width_m(), area.height_m());
  const double short_m = std::min(area.width_m(), area.height_m());
  const double ideal = std::sqrt(static_cast<double>(n) * short_m / long_m);
  const std::size_t bands = std::clamp<std::size_t>(static_cast<std::size_t>(std::floor(ideal + 1e-9)), 1, n);
  g.cells.assign(bands, n / bands);
  for (std::size_t b = 0; b < n % bands; ++b) ++g.cells[b];
  return g;
}

std::vector<raft::Sector> PartitionArea(const Rect& area, std::span<const std::string> drones) {
  const PartitionGrid g = PartitionGridFor(area, drones.size());
  // (u, w): u along the longer side (the cells of a band), w across it (the bands).
  const double u_min = g.bands_along_y ? area.x_min_m : area.y_min_m;
  const double u_max = g.bands_along_y ? area.x_max_m : area.y_max_m;
  const double w_min = g.bands_along_y ? area.y_min_m : area.x_min_m;
  const double w_max = g.bands_along_y ? area.y_max_m : area.x_max_m;
  std::vector<raft::Sector> out;
  out.reserve(drones.size());
  std::size_t i = 0;
  const std::size_t bands = g.cells.size();
  for (std::size_t b = 0; b < bands; ++b) {
    // The last band and cell end exactly on the area's edge (no rounding gap).
    const double w0 = w_min + (w_max - w_min) * static_cast<double>(b) / static_cast<double>(bands);
    const double w1 = b + 1 == bands
                          ? w_max
                          : w_min + (w_max - w_min) * static_cast<double>(b + 1) / static_cast<double>(bands);
    const std::size_t k = g.cells[b];
    for (std::size_t c = 0; c < k; ++c, ++i) {
      const double u0 = u_min + (u_max - u_min) * static_cast<double>(c) / static_cast<double>(k);
      const double u1 =
          c + 1 == k ? u_max : u_min + (u_max - u_min) * static_cast<double>(c + 1) / static_cast<double>(k);
      raft::Sector s;
      s.drone = drones[i];
      if (g.bands_along_y) {
        s.x_min_m = u0, s.x_max_m = u1, s.y_min_m = w0, s.y_max_m = w1;
      } else {
        s.x_min_m = w0, s.x_max_m = w1, s.y_min_m = u0, s.y_max_m = u1;
      }
      out.push_back(std::move(s));
    }
  }
  return out;
}

std::vector<std::size_t> PartitionOrder(const Rect& area, std::span<const std::string> drones,
                                        std::span<const Eigen::Vector2d> positions_m) {
  SWARMBOX_CHECK(drones.size() == positions_m.size());
  const PartitionGrid g = PartitionGridFor(area, drones.size());
  const int u_axis = g.bands_along_y ? 0 : 1;
  const int w_axis = 1 - u_axis;
  std::vector<std::size_t> order(drones.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  const auto by = [&](int axis) {
    return [&, axis](std::size_t a, std::size_t b) {
      const double pa = positions_m[a][axis], pb = positions_m[b][axis];
      if (pa != pb) return pa < pb;
      return drones[a] < drones[b];
    };
  };
  std::sort(order.begin(), order.end(), by(w_axis));
  std::size_t from = 0;
  for (const std::size_t k : g.cells) {
    const auto first = order.begin() + static_cast<std::ptrdiff_t>(from);
    std::sort(first, first + static_cast<std::ptrdiff_t>(k), by(u_axis));
    from += k;
  }
  return order;
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
