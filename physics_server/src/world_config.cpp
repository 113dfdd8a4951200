#include "swarmbox/physics/world_config.hpp"

#include <cmath>
#include <numbers>
#include <set>

#include "detail/yaml_read.hpp"

namespace swarmbox::physics {
namespace {

using detail::Checked;
using detail::Nested;
using yaml::MapReader;
using yaml::Node;

Status ReadObstacles(const Node& list, std::vector<ObstacleBox>* out) {
  if (list.is_null()) return Ok{};
  if (!list.is_sequence()) return Error(ErrorCode::kInvalidArgument, "'obstacles' must be a list", list.Where());
  std::set<std::string> ids;
  for (const Node& item : list.items()) {
    MapReader r(item, "obstacle");
    ObstacleBox box;
    double yaw_deg = 0;
    r.Required("id", &box.id).Required("center_m", &box.center_m).Required("size_m", &box.size_m)
        .Optional("yaw_deg", &yaw_deg);
    if (auto s = r.Finish(); !s) return s.error();
    if (box.size_m.x <= 0 || box.size_m.y <= 0 || box.size_m.z <= 0) {
      return Error(ErrorCode::kInvalidArgument, "obstacle '" + box.id + "': size_m must be positive",
                   item.Find("size_m")->Where());
    }
    if (!ids.insert(box.id).second) {
      return Error(ErrorCode::kInvalidArgument, "duplicate obstacle id '" + box.id + "'", item.Find("id")->Where());
    }
    box.yaw_rad = yaw_deg * std::numbers::pi / 180.0;
    out->push_back(box);
  }
  return Ok{};
}

Status ReadVictims(const Node& list, std::vector<Victim>* out) {
  if (list.is_null()) return Ok{};
  if (!list.is_sequence()) return Error(ErrorCode::kInvalidArgument, "'victims' must be a list", list.Where());
  std::set<std::string> ids;
  for (const Node& item : list.items()) {
    MapReader r(item, "victim");
    Victim v;
    double heading_deg = 0;
    r.Required("id", &v.id).Required("x_m", &v.x_m).Required("y_m", &v.y_m).Optional("heading_deg", &heading_deg);
    if (auto s = r.Finish(); !s) return s.error();
    if (!ids.insert(v.id).second) {
      return Error(ErrorCode::kInvalidArgument, "duplicate victim id '" + v.id + "'", item.Find("id")->Where());
    }
    v.heading_rad = heading_deg * std::numbers::pi / 180.0;
    out->push_back(v);
  }
  return Ok{};
}

}  // namespace

Result<WorldConfig> ParseWorld(const yaml::Node& root, std::string source) {
  WorldConfig w;
  w.source = std::move(source);
  MapReader r(root, "world");
  r.Required("name", &w.name);
  Nested(r, "geofence", "geofence", false, [&w](MapReader& g, const Node& n) {
    Checked(g, n).Positive("size_x_m", &w.size_x_m).Positive("size_y_m", &w.size_y_m);
  });
  Checked(r, root).Positive("gravity_m_s2", &w.gravity_m_s2, false).Positive("air_density_kg_m3", &w.air_density_kg_m3, false);
  r.Optional("ground_texture_seed", &w.ground_texture_seed);
  if (const Node* obstacles = r.Child("obstacles"); obstacles && r.ok()) {
    if (auto s = ReadObstacles(*obstacles, &w.obstacles); !s) r.Fail(s.error());
  }
  if (const Node* victims = r.Child("victims"); victims && r.ok()) {
    if (auto s = ReadVictims(*victims, &w.victims); !s) r.Fail(s.error());
  }
  Nested(r, "wind", "wind", false, [&w](MapReader& g, const Node& n) {
    g.Optional("mean_m_s", &w.wind.mean_m_s);
    Checked(g, n).NonNegative("gust_std_m_s", &w.wind.gust_std_m_s).Positive("gust_time_s", &w.wind.gust_time_s, false);
  });
  r.Optional("magnetic_field_gauss", &w.magnetic_field_gauss);
  Nested(r, "home", "home", false, [&w](MapReader& g, const Node&) {
    g.Required("lat_deg", &w.home_lat_deg).Required("lon_deg", &w.home_lon_deg).Optional("alt_m", &w.home_alt_m);
  });
  if (auto s = r.Finish(); !s) return s.error().Context("world");
  if (std::abs(w.home_lat_deg) > 89.0 || std::abs(w.home_lon_deg) > 180.0) {
    return Error(ErrorCode::kInvalidArgument, "world: home lat/lon out of range", root.Find("home")->Where());
  }
  for (const Victim& v : w.victims) {
    if (std::abs(v.x_m) > w.size_x_m / 2 || std::abs(v.y_m) > w.size_y_m / 2) {
      return Error(ErrorCode::kInvalidArgument, "world: victim '" + v.id + "' lies outside the geofence",
                   root.Find("victims")->Where());
    }
  }
  return w;
}

Result<WorldConfig> LoadWorld(const std::string& path) {
  auto doc = yaml::ParseFile(path);
  if (!doc) return doc.error();
  return ParseWorld(*doc, path);
}

}  // namespace swarmbox::physics
