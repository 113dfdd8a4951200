#include "swarmbox/physics/world_config.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <set>
#include <string_view>

#include "swarmbox/airframe/yaml_read.hpp"

namespace swarmbox::physics {
namespace {

using airframe::detail::Checked;
using airframe::detail::Nested;
using yaml::MapReader;
using yaml::Node;

// An enum value and its name in world files; a table of them serves both reading and ToString.
template <typename E>
struct Named {
  E value;
  const char* name;
};

template <typename E, std::size_t N>
const char* NameIn(const std::array<Named<E>, N>& table, E value) {
  for (const Named<E>& n : table) {
    if (n.value == value) return n.name;
  }
  return table[0].name;  // not an enumerator: the first one's name
}

template <typename E, std::size_t N>
Status ReadEnum(const Node& map, std::string_view key, const std::array<Named<E>, N>& values, std::string_view what,
                E* out) {
  const Node* n = map.Find(std::string(key));
  if (n == nullptr) return Ok{};
  std::string text;
  if (auto s = yaml::Decode(*n, &text); !s) return s;
  std::string names;
  for (const Named<E>& v : values) {
    if (text == v.name) {
      *out = v.value;
      return Ok{};
    }
    names += (names.empty() ? "" : "|") + std::string(v.name);
  }
  return Error(ErrorCode::kInvalidArgument,
               std::string(what) + " " + std::string(key) + " '" + text + "' is not one of " + names, n->Where());
}

// [b, g, r], each 0..255.
Status ReadBgr(const Node& map, std::string_view key, std::string_view what, std::optional<Bgr>* out) {
  const Node* n = map.Find(std::string(key));
  if (n == nullptr) return Ok{};
  std::array<int, 3> v{};
  if (auto s = yaml::Decode(*n, &v); !s) return s;
  Bgr bgr{};
  for (std::size_t i = 0; i < 3; ++i) {
    if (v[i] < 0 || v[i] > 255) {
      return Error(ErrorCode::kInvalidArgument, std::string(what) + " " + std::string(key) + " must be 0..255 each",
                   n->Where());
    }
    bgr[i] = static_cast<std::uint8_t>(v[i]);
  }
  *out = bgr;
  return Ok{};
}

constexpr std::array kObstacleKinds = {Named<ObstacleKind>{ObstacleKind::kBox, "box"},
                                       Named<ObstacleKind>{ObstacleKind::kTree, "tree"}};
constexpr std::array kPoses = {Named<VictimPose>{VictimPose::kLying, "lying"},
                               Named<VictimPose>{VictimPose::kSitting, "sitting"},
                               Named<VictimPose>{VictimPose::kCurled, "curled"},
                               Named<VictimPose>{VictimPose::kStanding, "standing"}};
constexpr std::array kTerrains = {
    Named<TerrainKind>{TerrainKind::kGrass, "grass"}, Named<TerrainKind>{TerrainKind::kSoil, "soil"},
    Named<TerrainKind>{TerrainKind::kGravel, "gravel"}, Named<TerrainKind>{TerrainKind::kRubble, "rubble"},
    Named<TerrainKind>{TerrainKind::kMixed, "mixed"}};
constexpr std::array kDistractorKinds = {
    Named<DistractorKind>{DistractorKind::kTarp, "tarp"}, Named<DistractorKind>{DistractorKind::kCone, "cone"},
    Named<DistractorKind>{DistractorKind::kBackpack, "backpack"},
    Named<DistractorKind>{DistractorKind::kDebris, "debris"}, Named<DistractorKind>{DistractorKind::kRock, "rock"}};

// A list section's items (absent: none), each read by read_item; items with an id (obstacles,
// victims) must not repeat one: "duplicate <what> id".
template <typename T>
Status ReadList(const Node& list, const std::string& key, const std::string& what, Result<T> (*read_item)(const Node&),
                std::vector<T>* out) {
  if (list.is_null()) return Ok{};
  if (!list.is_sequence()) return Error(ErrorCode::kInvalidArgument, "'" + key + "' must be a list", list.Where());
  std::set<std::string> ids;
  for (const Node& item : list.items()) {
    Result<T> x = read_item(item);
    if (!x) return x.error();
    if constexpr (requires(T& t) { t.id; }) {
      if (!ids.insert(x->id).second) {
        return Error(ErrorCode::kInvalidArgument, "duplicate " + what + " id '" + x->id + "'", item.Find("id")->Where());
      }
    }
    out->push_back(std::move(*x));
  }
  return Ok{};
}

Result<ObstacleBox> ReadObstacle(const Node& item) {
  MapReader r(item, "obstacle");
  ObstacleBox box;
  double yaw_deg = 0;
  std::string kind_text;
  r.Required("id", &box.id).Required("center_m", &box.center_m).Required("size_m", &box.size_m)
      .Optional("yaw_deg", &yaw_deg).Optional("kind", &kind_text);
  if (auto s = r.Finish(); !s) return s.error();
  if (auto s = ReadEnum(item, "kind", kObstacleKinds, "obstacle '" + box.id + "':", &box.kind); !s) return s.error();
  if (box.size_m.x <= 0 || box.size_m.y <= 0 || box.size_m.z <= 0) {
    return Error(ErrorCode::kInvalidArgument, "obstacle '" + box.id + "': size_m must be positive",
                 item.Find("size_m")->Where());
  }
  box.yaw_rad = yaw_deg * std::numbers::pi / 180.0;
  return box;
}

Result<Victim> ReadVictim(const Node& item) {
  MapReader r(item, "victim");
  Victim v;
  double heading_deg = 0;
  std::string pose_text;
  std::array<int, 3> clothing{};
  r.Required("id", &v.id).Required("x_m", &v.x_m).Required("y_m", &v.y_m).Optional("heading_deg", &heading_deg)
      .Optional("pose", &pose_text).Optional("clothing_bgr", &clothing).Optional("cover", &v.cover)
      .Optional("height_m", &v.height_m);
  if (auto s = r.Finish(); !s) return s.error();
  const std::string what = "victim '" + v.id + "':";
  if (auto s = ReadEnum(item, "pose", kPoses, what, &v.pose); !s) return s.error();
  if (auto s = ReadBgr(item, "clothing_bgr", what, &v.clothing_bgr); !s) return s.error();
  if (!(v.height_m >= 0.8 && v.height_m <= 2.2)) {
    return Error(ErrorCode::kInvalidArgument, what + " height_m must be within 0.8..2.2", item.Find("height_m")->Where());
  }
  if (!(v.cover >= 0 && v.cover <= 1)) {
    return Error(ErrorCode::kInvalidArgument, what + " cover must be within 0..1", item.Find("cover")->Where());
  }
  v.heading_rad = heading_deg * std::numbers::pi / 180.0;
  return v;
}

Result<Distractor> ReadDistractor(const Node& item) {
  MapReader r(item, "distractor");
  Distractor d;
  std::string kind_text;
  double heading_deg = 0;
  std::array<int, 3> colour{};
  r.Required("kind", &kind_text).Required("x_m", &d.x_m).Required("y_m", &d.y_m).Optional("heading_deg", &heading_deg)
      .Optional("size_m", &d.size_m).Optional("colour_bgr", &colour);
  if (auto s = r.Finish(); !s) return s.error();
  if (auto s = ReadEnum(item, "kind", kDistractorKinds, "distractor", &d.kind); !s) return s.error();
  std::optional<Bgr> bgr;
  if (auto s = ReadBgr(item, "colour_bgr", "distractor", &bgr); !s) return s.error();
  d.colour_bgr = bgr.value_or(DefaultColour(d.kind));
  if (d.size_m < 0) {
    return Error(ErrorCode::kInvalidArgument, "distractor size_m must be positive", item.Find("size_m")->Where());
  }
  if (d.size_m == 0) d.size_m = DefaultSizeM(d.kind);
  d.heading_rad = heading_deg * std::numbers::pi / 180.0;
  return d;
}

// The obstacles, victims and distractors (each list read only while the reader is still ok).
void ReadWorldLists(MapReader& r, WorldConfig* w) {
  if (const Node* obstacles = r.Child("obstacles"); obstacles && r.ok()) {
    if (auto s = ReadList(*obstacles, "obstacles", "obstacle", ReadObstacle, &w->obstacles); !s) r.Fail(s.error());
  }
  if (const Node* victims = r.Child("victims"); victims && r.ok()) {
    if (auto s = ReadList(*victims, "victims", "victim", ReadVictim, &w->victims); !s) r.Fail(s.error());
  }
  if (const Node* distractors = r.Child("distractors"); distractors && r.ok()) {
    if (auto s = ReadList(*distractors, "distractors", "distractor", ReadDistractor, &w->distractors); !s) r.Fail(s.error());
  }
}

// The optional sections: lighting, terrain, wind, the magnetic field and home.
void ReadWorldSections(MapReader& r, WorldConfig* w) {
  Nested(r, "lighting", "lighting", false, [w](MapReader& g, const Node&) {
    Lighting l;
    g.Optional("time_of_day_h", &l.time_of_day_h)
        .Optional("overcast", &l.overcast)
        .Optional("air_temperature_c", &l.air_temperature_c);
    w->lighting = l;
  });
  Nested(r, "terrain", "terrain", false, [w](MapReader& g, const Node&) {
    Terrain t;
    std::string kind_text;
    g.Optional("kind", &kind_text).Optional("water_fraction", &t.water_fraction);
    w->terrain = t;
  });
  Nested(r, "wind", "wind", false, [w](MapReader& g, const Node& n) {
    g.Optional("mean_m_s", &w->wind.mean_m_s);
    Checked(g, n).NonNegative("gust_std_m_s", &w->wind.gust_std_m_s).Positive("gust_time_s", &w->wind.gust_time_s, false);
  });
  r.Optional("magnetic_field_gauss", &w->magnetic_field_gauss);
  Nested(r, "home", "home", false, [w](MapReader& g, const Node&) {
    g.Required("lat_deg", &w->home_lat_deg).Required("lon_deg", &w->home_lon_deg).Optional("alt_m", &w->home_alt_m);
  });
}

// The lighting's ranges; the terrain's kind (read here: it needs the table) and water fraction.
Status CheckLook(const Node& root, WorldConfig* w) {
  if (w->lighting) {
    const Node& n = *root.Find("lighting");
    if (!(w->lighting->time_of_day_h >= 0 && w->lighting->time_of_day_h <= 24)) {
      return Error(ErrorCode::kInvalidArgument, "world: lighting time_of_day_h must be within 0..24", n.Where());
    }
    if (!(w->lighting->overcast >= 0 && w->lighting->overcast <= 1)) {
      return Error(ErrorCode::kInvalidArgument, "world: lighting overcast must be within 0..1", n.Where());
    }
    if (!(w->lighting->air_temperature_c >= -40 && w->lighting->air_temperature_c <= 50)) {
      return Error(ErrorCode::kInvalidArgument, "world: lighting air_temperature_c must be within -40..50",
                   n.Where());
    }
  }
  if (w->terrain) {
    const Node& n = *root.Find("terrain");
    if (auto s = ReadEnum(n, "kind", kTerrains, "world: terrain", &w->terrain->kind); !s) return s.error();
    if (!(w->terrain->water_fraction >= 0 && w->terrain->water_fraction < 1)) {
      return Error(ErrorCode::kInvalidArgument, "world: terrain water_fraction must be within 0..1 (below 1)", n.Where());
    }
  }
  return Ok{};
}

// Home on the globe; every victim and distractor inside the geofence.
Status CheckInsideGeofence(const Node& root, const WorldConfig& w) {
  if (std::abs(w.home_lat_deg) > 89.0 || std::abs(w.home_lon_deg) > 180.0) {
    return Error(ErrorCode::kInvalidArgument, "world: home lat/lon out of range", root.Find("home")->Where());
  }
  for (const Victim& v : w.victims) {
    if (std::abs(v.x_m) > w.size_x_m / 2 || std::abs(v.y_m) > w.size_y_m / 2) {
      return Error(ErrorCode::kInvalidArgument, "world: victim '" + v.id + "' lies outside the geofence",
                   root.Find("victims")->Where());
    }
  }
  for (const Distractor& d : w.distractors) {
    if (std::abs(d.x_m) > w.size_x_m / 2 || std::abs(d.y_m) > w.size_y_m / 2) {
      return Error(ErrorCode::kInvalidArgument,
                   std::string("world: a ") + NameIn(kDistractorKinds, d.kind) + " distractor lies outside the geofence",
                   root.Find("distractors")->Where());
    }
  }
  return Ok{};
}

}  // namespace

const char* ToString(ObstacleKind kind) { return NameIn(kObstacleKinds, kind); }

const char* ToString(VictimPose pose) { return NameIn(kPoses, pose); }

const char* ToString(TerrainKind kind) { return NameIn(kTerrains, kind); }

const char* ToString(DistractorKind kind) { return NameIn(kDistractorKinds, kind); }

double DefaultSizeM(DistractorKind kind) {
  switch (kind) {
    case DistractorKind::kTarp: return 2.0;      // a 2 x 1.5 m tarpaulin
    case DistractorKind::kCone: return 0.5;      // a traffic cone's base, seen from above
    case DistractorKind::kBackpack: return 0.6;
    case DistractorKind::kDebris: return 1.5;    // a plank, a door, sheet metal
    case DistractorKind::kRock: return 1.0;
  }
  return 1.0;
}

Bgr DefaultColour(DistractorKind kind) {
  switch (kind) {
    case DistractorKind::kTarp: return {20, 90, 230};      // orange
    case DistractorKind::kCone: return {10, 80, 250};      // safety orange
    case DistractorKind::kBackpack: return {40, 40, 200};  // red
    case DistractorKind::kDebris: return {120, 130, 140};  // weathered wood / metal
    case DistractorKind::kRock: return {190, 200, 205};    // pale limestone
  }
  return {128, 128, 128};
}

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
  ReadWorldLists(r, &w);
  ReadWorldSections(r, &w);
  if (auto s = r.Finish(); !s) return s.error().Context("world");
  if (auto s = CheckLook(root, &w); !s) return s.error();
  if (auto s = CheckInsideGeofence(root, w); !s) return s.error();
  return w;
}

Result<WorldConfig> LoadWorld(const std::string& path) {
  auto doc = yaml::ParseFile(path);
  if (!doc) return doc.error();
  return ParseWorld(*doc, path);
}

}  // namespace swarmbox::physics
