#include "swarmbox/worlds/generator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <sstream>
#include <vector>

namespace swarmbox::worlds {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kVictimSpacingM = 8.0;   // > MissionState's 5 m merge radius
constexpr double kLaunchClearM = 15.0;    // obstacles keep the launch area around the origin free
constexpr double kBorderM = 5.0;

std::uint64_t Mix(std::uint64_t x) {  // splitmix64
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  std::string s = buf;
  while (s.back() == '0') s.pop_back();
  if (s.back() == '.') s.pop_back();
  if (s == "-0") s = "0";
  return s;
}

struct Disc {
  double x, y, r;
};

struct Placer {
  std::mt19937_64 rng;
  double half_x, half_y;
  std::vector<Disc> obstacles, victims, distractors;

  double U(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
  int I(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); }
  bool Chance(double p) { return U(0, 1) < p; }

  static bool Clear(const std::vector<Disc>& discs, double x, double y, double r, double gap) {
    return std::all_of(discs.begin(), discs.end(), [&](const Disc& d) { return std::hypot(d.x - x, d.y - y) >= d.r + r + gap; });
  }
};

struct Clothing {
  int b, g, r;
};
// Greens, browns and greys (hard to see), and bright colours (easy), as people wear them.
constexpr Clothing kClothes[] = {{45, 85, 55},  {60, 110, 80},  {40, 70, 100},  {50, 80, 120},  {90, 90, 95},
                                 {140, 140, 145}, {35, 35, 40},   {120, 70, 40},  {30, 30, 190},  {20, 140, 240},
                                 {200, 110, 30}, {40, 200, 230}, {150, 60, 140}, {210, 210, 215}, {70, 120, 150}};

const char* Pose(Placer& p, WorldKind kind) {
  const double u = p.U(0, 1);
  switch (kind) {
    case WorldKind::kRubbleField: return u < 0.5 ? "lying" : u < 0.8 ? "curled" : u < 0.95 ? "sitting" : "standing";
    case WorldKind::kForestEdge: return u < 0.4 ? "lying" : u < 0.6 ? "curled" : u < 0.85 ? "sitting" : "standing";
    case WorldKind::kOpenField: return u < 0.45 ? "lying" : u < 0.65 ? "curled" : u < 0.85 ? "sitting" : "standing";
  }
  return "lying";
}

}  // namespace

std::string_view KindName(WorldKind kind) {
  switch (kind) {
    case WorldKind::kRubbleField: return "rubble_field";
    case WorldKind::kForestEdge: return "forest_edge";
    case WorldKind::kOpenField: return "open_field";
  }
  return "rubble_field";
}

Result<GenerateSpec> ParseGenerateSpec(const yaml::Node& world) {
  GenerateSpec spec;
  yaml::MapReader r(world, "world");
  std::string kind;
  std::vector<double> size;
  std::uint64_t seed = 0;
  r.Required("generate", &kind).Optional("size_m", &size).Optional("victims", &spec.victims)
      .Optional("obstacles", &spec.obstacles).Optional("distractors", &spec.distractors).Optional("seed", &seed);
  SWARMBOX_TRY(r.Finish());
  const WorldKind kinds[] = {WorldKind::kRubbleField, WorldKind::kForestEdge, WorldKind::kOpenField};
  const auto* it = std::find_if(std::begin(kinds), std::end(kinds), [&](WorldKind k) { return KindName(k) == kind; });
  if (it == std::end(kinds)) {
    return Error(ErrorCode::kInvalidArgument, "world: generate '" + kind + "' is not one of rubble_field|forest_edge|open_field",
                 world.Find("generate")->Where());
  }
  spec.kind = *it;
  if (const yaml::Node* n = world.Find("size_m")) {
    if (size.size() != 2 || !(size[0] >= 40 && size[0] <= 2000) || !(size[1] >= 40 && size[1] <= 2000)) {
      return Error(ErrorCode::kInvalidArgument, "world: size_m must be [X, Y] in metres, each 40..2000", n->Where());
    }
    spec.size_m = {size[0], size[1]};
  }
  auto range = [&](const char* key, int value, int hi) -> Status {
    if (value >= 0 && value <= hi) return Ok{};
    return Error(ErrorCode::kInvalidArgument, "world: " + std::string(key) + " must be 0.." + std::to_string(hi),
                 world.Find(key)->Where());
  };
  SWARMBOX_TRY(range("victims", spec.victims, 100));
  SWARMBOX_TRY(range("obstacles", spec.obstacles, 2000));
  SWARMBOX_TRY(range("distractors", spec.distractors, 2000));
  if (world.Find("seed") != nullptr) spec.seed = seed;
  return spec;
}

yaml::Node ToNode(const GenerateSpec& spec) {
  yaml::Node n = yaml::Node::Mapping();
  n.Set("generate", yaml::Node::Scalar(std::string(KindName(spec.kind))));
  yaml::Node size = yaml::Node::Sequence();
  size.Append(yaml::Node::Scalar(Num(spec.size_m[0])));
  size.Append(yaml::Node::Scalar(Num(spec.size_m[1])));
  n.Set("size_m", std::move(size));
  n.Set("victims", yaml::Node::Scalar(std::to_string(spec.victims)));
  n.Set("obstacles", yaml::Node::Scalar(std::to_string(spec.obstacles)));
  n.Set("distractors", yaml::Node::Scalar(std::to_string(spec.distractors)));
  if (spec.seed) n.Set("seed", yaml::Node::Scalar(std::to_string(*spec.seed)));
  return n;
}

std::uint64_t WorldSeed(const GenerateSpec& spec, std::uint64_t trial_seed) {
  return spec.seed ? *spec.seed : Mix(trial_seed ^ 0x5EEDF00DULL) % 1'000'000'000ULL;
}

namespace {

// The forest edge: a wandering line x = At(y); trees dense west of it, sparse east.
struct ForestEdge {
  double x0 = 0;
  double amp = 0;
  double phase = 0;
  double wave = 0;
  double At(double y) const { return x0 + amp * std::sin(wave * y + phase); }
};

ForestEdge DrawForestEdge(Placer& p, const GenerateSpec& spec) {
  ForestEdge e;
  e.x0 = p.U(-0.15, 0.15) * spec.size_m[0];
  e.amp = p.U(0.03, 0.1) * spec.size_m[0];
  e.phase = p.U(0, 2 * kPi);
  e.wave = p.U(0.5, 1.5) * 2 * kPi / spec.size_m[1];
  return e;
}

// Obstacle i (0-based) at a free spot, as a line of `obstacles:`; false when none was found.
bool PlaceObstacle(Placer& p, const GenerateSpec& spec, const ForestEdge& edge, int i, std::ostringstream& obstacles) {
  const WorldKind kind = spec.kind;
  for (int attempt = 0; attempt < 400; ++attempt) {
    const bool tree = kind == WorldKind::kForestEdge ? p.Chance(0.9) : kind == WorldKind::kOpenField && p.Chance(0.3);
    double sx, sy, sz;
    if (tree) {
      sx = sy = p.U(3.0, 8.0), sz = p.U(6.0, 15.0);
    } else if (kind == WorldKind::kRubbleField) {
      sx = p.U(2.0, 10.0), sy = p.U(1.0, 6.0), sz = p.U(1.0, 5.0);
    } else {
      sx = p.U(2.0, 6.0), sy = p.U(2.0, 4.0), sz = p.U(1.5, 3.5);  // sheds, bales, vehicles
    }
    const double r = std::hypot(sx, sy) / 2;
    const double x = p.U(-p.half_x + kBorderM + r, p.half_x - kBorderM - r);
    const double y = p.U(-p.half_y + kBorderM + r, p.half_y - kBorderM - r);
    if (std::hypot(x, y) < kLaunchClearM + r) continue;
    if (kind == WorldKind::kForestEdge && tree && x > edge.At(y) && !p.Chance(0.12)) continue;  // sparse east of the edge
    if (!Placer::Clear(p.obstacles, x, y, r, 0.5)) continue;
    p.obstacles.push_back({x, y, r});
    obstacles << "  - {id: " << (tree ? "tree_" : "block_") << i + 1 << (tree ? ", kind: tree" : "") << ", center_m: [" << Num(x)
              << ", " << Num(y) << ", " << Num(sz / 2) << "], size_m: [" << Num(sx) << ", " << Num(sy) << ", " << Num(sz)
              << "], yaw_deg: " << Num(tree ? 0 : p.U(0, 180)) << "}\n";
    return true;
  }
  return false;
}

Status PlaceObstacles(Placer& p, const GenerateSpec& spec, const ForestEdge& edge, std::ostringstream& obstacles) {
  for (int i = 0; i < spec.obstacles; ++i) {
    if (!PlaceObstacle(p, spec, edge, i, obstacles)) {
      return Error(ErrorCode::kInvalidArgument, "world: no free spot for obstacle " + std::to_string(i + 1) + " of " +
                                                    std::to_string(spec.obstacles) + " in " + Num(spec.size_m[0]) + " x " +
                                                    Num(spec.size_m[1]) + " m: fewer obstacles or a larger size_m");
    }
  }
  return Ok{};
}

// Victim i (0-based) at a free spot, as a line of `victims:`; false when none was found.
bool PlaceVictim(Placer& p, const GenerateSpec& spec, const ForestEdge& edge, int i, std::ostringstream& victims) {
  const WorldKind kind = spec.kind;
  for (int attempt = 0; attempt < 2000; ++attempt) {
    const double margin = kBorderM + 2;
    double x = p.U(-p.half_x + margin, p.half_x - margin);
    const double y = p.U(-p.half_y + margin, p.half_y - margin);
    if (kind == WorldKind::kForestEdge && attempt < 1500) {  // near the edge, on either side
      x = std::clamp(edge.At(y) + p.U(-25, 25), -p.half_x + margin, p.half_x - margin);
    }
    if (!Placer::Clear(p.victims, x, y, 0, kVictimSpacingM) || !Placer::Clear(p.obstacles, x, y, 1.0, 3.0)) continue;
    p.victims.push_back({x, y, 1.0});
    const Clothing& c = kClothes[static_cast<std::size_t>(p.I(0, static_cast<int>(std::size(kClothes)) - 1))];
    const double cover = kind == WorldKind::kRubbleField ? p.U(0.0, 0.6) : kind == WorldKind::kForestEdge ? p.U(0.0, 0.5) : p.U(0.0, 0.25);
    victims << "  - {id: victim_" << i + 1 << ", x_m: " << Num(x) << ", y_m: " << Num(y) << ", heading_deg: " << Num(p.U(0, 360))
            << ", pose: " << Pose(p, kind) << ", height_m: " << Num(p.U(1.45, 1.95)) << ", clothing_bgr: [" << c.b << ", " << c.g
            << ", " << c.r << "], cover: " << Num(cover) << "}\n";
    return true;
  }
  return false;
}

Status PlaceVictims(Placer& p, const GenerateSpec& spec, const ForestEdge& edge, std::ostringstream& victims) {
  for (int i = 0; i < spec.victims; ++i) {
    if (!PlaceVictim(p, spec, edge, i, victims)) {
      return Error(ErrorCode::kInvalidArgument, "world: no spot for victim " + std::to_string(i + 1) + " of " + std::to_string(spec.victims) +
                                                    " (8 m apart, 3 m from obstacles) in " + Num(spec.size_m[0]) + " x " +
                                                    Num(spec.size_m[1]) + " m: fewer victims or obstacles, or a larger size_m");
    }
  }
  return Ok{};
}

// A distractor's size and colour keys, by its kind.
void DistractorLook(Placer& p, const std::string& w, std::ostringstream& distractors) {
  if (w == "tarp") {  // orange, red, blue and green tarpaulins
    const int t = p.I(0, 3);
    distractors << ", size_m: " << Num(p.U(1.5, 3.5)) << ", colour_bgr: "
                << (t == 0 ? "[20, 90, 230]" : t == 1 ? "[30, 30, 200]" : t == 2 ? "[170, 90, 30]" : "[50, 110, 60]");
  } else if (w == "backpack") {
    const int t = p.I(0, 3);
    distractors << ", colour_bgr: " << (t == 0 ? "[40, 40, 200]" : t == 1 ? "[30, 120, 240]" : t == 2 ? "[60, 80, 70]" : "[120, 60, 30]");
  } else if (w == "rock") {
    distractors << ", size_m: " << Num(p.U(0.5, 1.6));
  } else if (w == "debris") {
    distractors << ", size_m: " << Num(p.U(0.8, 2.5)) << ", colour_bgr: [" << p.I(60, 150) << ", " << p.I(70, 150) << ", " << p.I(80, 160) << "]";
  }
}

// Distractors where there is room (one without a spot is left out).
void PlaceDistractors(Placer& p, const GenerateSpec& spec, std::ostringstream& distractors) {
  const WorldKind kind = spec.kind;
  for (int i = 0; i < spec.distractors; ++i) {
    for (int attempt = 0; attempt < 400; ++attempt) {
      const double x = p.U(-p.half_x + 1, p.half_x - 1), y = p.U(-p.half_y + 1, p.half_y - 1);
      if (!Placer::Clear(p.victims, x, y, 1.0, 2.0) || !Placer::Clear(p.obstacles, x, y, 0.5, 0.5)) continue;
      const double u = p.U(0, 1);
      const char* what = kind == WorldKind::kRubbleField ? (u < 0.35 ? "debris" : u < 0.55 ? "tarp" : u < 0.75 ? "rock" : u < 0.9 ? "cone" : "backpack")
                                                         : (u < 0.25 ? "tarp" : u < 0.45 ? "rock" : u < 0.65 ? "backpack" : u < 0.8 ? "debris" : "cone");
      distractors << "  - {kind: " << what << ", x_m: " << Num(x) << ", y_m: " << Num(y) << ", heading_deg: " << Num(p.U(0, 360));
      DistractorLook(p, what, distractors);
      distractors << "}\n";
      p.distractors.push_back({x, y, 1.0});
      break;
    }
  }
}

// The world file around the placed objects; draws the lighting and the wind.
std::string WorldYaml(Placer& p, const GenerateSpec& spec, std::uint64_t seed, const std::string& obstacles,
                      const std::string& victims, const std::string& distractors) {
  const WorldKind kind = spec.kind;
  const char* terrain = kind == WorldKind::kRubbleField ? "{kind: rubble, water_fraction: 0}"
                        : kind == WorldKind::kForestEdge ? "{kind: mixed, water_fraction: 0.03}"
                                                         : "{kind: grass, water_fraction: 0.02}";
  std::ostringstream out;
  out << "# Generated by swarmbox::worlds (" << KindName(kind) << ", seed " << seed << "): do not edit, change the trial's world: recipe\n";
  out << "name: " << KindName(kind) << "_" << seed << "\n";
  out << "geofence: {size_x_m: " << Num(spec.size_m[0]) << ", size_y_m: " << Num(spec.size_m[1]) << "}\n";
  out << "ground_texture_seed: " << (Mix(seed ^ 0x7E47) % 1'000'000ULL) << "\n";
  out << "terrain: " << terrain << "\n";
  out << "lighting: {time_of_day_h: " << Num(p.U(7.0, 18.0)) << ", overcast: " << Num(p.U(0, 1)) << "}\n";
  out << "obstacles:" << (spec.obstacles == 0 ? " []\n" : "\n") << obstacles;
  out << "victims:" << (spec.victims == 0 ? " []\n" : "\n") << victims;
  out << "distractors:" << (spec.distractors == 0 ? " []\n" : "\n") << distractors;
  out << "wind: {mean_m_s: [" << Num(p.U(-2, 2)) << ", " << Num(p.U(-2, 2)) << ", 0.0], gust_std_m_s: " << Num(p.U(0.2, 0.8))
      << ", gust_time_s: 3.0}\n";
  out << "magnetic_field_gauss: [0.0, 0.21, -0.42]\n";
  out << "home: {lat_deg: 47.397742, lon_deg: 8.545594, alt_m: 488.0}\n";
  return out.str();
}

}  // namespace

Result<std::string> GenerateWorld(const GenerateSpec& spec, std::uint64_t seed) {
  Placer p{std::mt19937_64(Mix(seed)), spec.size_m[0] / 2, spec.size_m[1] / 2, {}, {}, {}};
  std::ostringstream obstacles, victims, distractors;
  const ForestEdge edge = DrawForestEdge(p, spec);
  SWARMBOX_TRY(PlaceObstacles(p, spec, edge, obstacles));
  SWARMBOX_TRY(PlaceVictims(p, spec, edge, victims));
  PlaceDistractors(p, spec, distractors);
  return WorldYaml(p, spec, seed, obstacles.str(), victims.str(), distractors.str());
}

}  // namespace swarmbox::worlds
