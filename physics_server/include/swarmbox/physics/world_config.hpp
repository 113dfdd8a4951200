// WorldConfig: the static world of a trial, read from trials/worlds/<name>.yaml.
// The schema is documented at the top of trials/worlds/open_field.yaml.
//
//   Result<WorldConfig> w = LoadWorld("trials/worlds/open_field.yaml");
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/physics/types.hpp"

namespace swarmbox::physics {

// An axis-aligned static box standing on the ground (yaw-rotated about its centre).
struct ObstacleBox {
  std::string id;
  Vec3 center_m;       // centre of the box [m, ENU]; a box resting on the ground has z = size.z/2
  Vec3 size_m;
  double yaw_rad = 0;
};

// A person lying on the ground, seen by the downward camera as a warm hi-vis figure.
struct Victim {
  std::string id;
  double x_m = 0;
  double y_m = 0;
  double heading_rad = 0;  // direction from feet to head, ENU yaw
};

// Wind: mean vector plus gusts, a first-order Gauss-Markov process per axis (std gust_std_m_s,
// correlation time gust_time_s), seeded from the world seed. Uniform in space.
struct WindConfig {
  Vec3 mean_m_s;
  double gust_std_m_s = 0;
  double gust_time_s = 2.0;
};

struct WorldConfig {
  std::string name;
  std::string source;
  double size_x_m = 200;           // geofence: |x| <= size_x_m/2, |y| <= size_y_m/2
  double size_y_m = 200;
  double gravity_m_s2 = 9.80665;
  std::uint64_t ground_texture_seed = 1;
  std::vector<ObstacleBox> obstacles;
  std::vector<Victim> victims;
  WindConfig wind;
  Vec3 magnetic_field_gauss{0.0, 0.21, -0.42};   // world-frame (ENU) Earth field [gauss]
  double home_lat_deg = 47.397742;               // ENU origin, WGS84
  double home_lon_deg = 8.545594;
  double home_alt_m = 488.0;                     // AMSL [m]
  double air_density_kg_m3 = 1.225;
};

Result<WorldConfig> ParseWorld(const yaml::Node& root, std::string source = {});
Result<WorldConfig> LoadWorld(const std::string& path);

}  // namespace swarmbox::physics
