// WorldConfig: the static world of a trial, read from trials/worlds/<name>.yaml.
// The schema is documented at the top of trials/worlds/open_field.yaml.
//
//   Result<WorldConfig> w = LoadWorld("trials/worlds/open_field.yaml");
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/physics/types.hpp"

namespace swarmbox::physics {

// 8-bit colour, blue first (OpenCV's order).
using Bgr = std::array<std::uint8_t, 3>;

// kBox: a block (rubble, wall, building). kTree: a tree whose box bounds trunk and crown (the
// camera draws a round crown over a trunk); for collisions and the radio's line of sight it is the
// box, like any other obstacle.
enum class ObstacleKind { kBox, kTree };

// An axis-aligned static box standing on the ground (yaw-rotated about its centre).
struct ObstacleBox {
  std::string id;
  Vec3 center_m;       // centre of the box [m, ENU]; a box resting on the ground has z = size.z/2
  Vec3 size_m;
  double yaw_rad = 0;
  ObstacleKind kind = ObstacleKind::kBox;
};

enum class VictimPose { kLying, kSitting, kCurled, kStanding };

// A person on the ground. Without clothing_bgr the camera draws today's hi-vis figure (orange
// body, amber head); with it, clothes of that colour, a skin-toned head, limbs by pose.
struct Victim {
  std::string id;
  double x_m = 0;
  double y_m = 0;
  double heading_rad = 0;  // direction from feet to head, ENU yaw
  VictimPose pose = VictimPose::kLying;
  double height_m = 1.75;  // body height [m] (children ~1.2, tall adults ~1.95)
  std::optional<Bgr> clothing_bgr{};
  double cover = 0;        // [0, 1]: share of the figure hidden under rubble or vegetation
};

// Time of day and cloud: the sun's direction (shadows) and the light's level and colour.
// Absent from the world: today's flat, shadowless light.
struct Lighting {
  double time_of_day_h = 12.0;  // local solar time [h], 0..24 (sun below the horizon: dusk light)
  double overcast = 0.0;        // [0, 1]: 0 clear (hard shadows), 1 fully overcast (no shadows)
  // Air temperature [deg C], -40..50: what the thermal camera sees surfaces warm above or cool
  // below (ThermalRenderer); the RGB camera ignores it.
  double air_temperature_c = 20.0;
};

// Ground cover of the procedural texture. Absent: today's grass with soil patches.
enum class TerrainKind { kGrass, kSoil, kGravel, kRubble, kMixed };
struct Terrain {
  TerrainKind kind = TerrainKind::kGrass;
  double water_fraction = 0.0;  // [0, 1): share of the ground under ponds/streams (with muddy edges)
};

// Things on the ground a detector may take for a person.
enum class DistractorKind { kTarp, kCone, kBackpack, kDebris, kRock };
struct Distractor {
  DistractorKind kind = DistractorKind::kTarp;
  double x_m = 0;
  double y_m = 0;
  double heading_rad = 0;
  double size_m = 0;       // longest side [m]; 0 in YAML = the kind's default
  Bgr colour_bgr{};        // absent in YAML = the kind's default
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
  std::vector<Distractor> distractors;
  std::optional<Lighting> lighting;
  std::optional<Terrain> terrain;
  WindConfig wind;
  Vec3 magnetic_field_gauss{0.0, 0.21, -0.42};   // world-frame (ENU) Earth field [gauss]
  double home_lat_deg = 47.397742;               // ENU origin, WGS84
  double home_lon_deg = 8.545594;
  double home_alt_m = 488.0;                     // AMSL [m]
  double air_density_kg_m3 = 1.225;
};

// Names as written in the YAML ("tree", "curled", "rubble", "tarp"...).
const char* ToString(ObstacleKind kind);
const char* ToString(VictimPose pose);
const char* ToString(TerrainKind kind);
const char* ToString(DistractorKind kind);
// A distractor kind's default size [m] and colour.
double DefaultSizeM(DistractorKind kind);
Bgr DefaultColour(DistractorKind kind);

Result<WorldConfig> ParseWorld(const yaml::Node& root, std::string source = {});
Result<WorldConfig> LoadWorld(const std::string& path);

}  // namespace swarmbox::physics
