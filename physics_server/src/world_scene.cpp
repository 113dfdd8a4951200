#include "swarmbox/physics/world_scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include "swarmbox/physics/detail/mix64.hpp"

namespace swarmbox::physics {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A surface's NIR look: base reflectance and the texture's amplitude at three scales (one cell,
// kMidScaleCells, kCoarseScaleCells), each a unit-variance value noise.
struct Look {
  double albedo;
  std::array<double, 3> amplitude;
};
constexpr int kMidScaleCells = 6;      // 0.3 m: stones, clods, bricks
constexpr int kCoarseScaleCells = 30;  // 1.5 m: patches
constexpr int kMixScaleCells = 120;    // 6 m: where mixed ground turns from grass to rubble
// Assumed NIR (940 nm) reflectances: vegetation is bright in the near infrared, soil darker;
// amplitudes say how much texture the matcher gets (grass at 5 cm cells is nearly uniform).
constexpr Look kGrassLook{0.45, {0.01, 0.015, 0.02}};
constexpr Look kSoilLook{0.30, {0.03, 0.04, 0.04}};
constexpr Look kGravelLook{0.35, {0.10, 0.04, 0.02}};
constexpr Look kRubbleLook{0.35, {0.08, 0.10, 0.05}};
constexpr Look kBoxLook{0.30, {0.08, 0.10, 0.05}};  // concrete, brick, debris
constexpr Look kTreeLook{0.50, {0.03, 0.04, 0.04}}; // foliage seen from above
constexpr Look kPersonLook{0.45, {0.03, 0.04, 0.04}};  // clothing and skin, folds
constexpr float kMinAlbedo = 0.02f, kMaxAlbedo = 0.95f;

// Salts: one noise field per use, so the ground, the boxes and the mix do not repeat each other.
enum Salt : std::uint64_t { kGroundSalt = 1, kObstacleSalt = 2, kPersonSalt = 3, kMixSalt = 4 };

using detail::Mix64;

// Unit-variance value at global lattice point (i, j) of one noise field.
float LatticeValue(std::uint64_t seed, std::uint64_t field, std::int64_t i, std::int64_t j) {
  const std::uint64_t h = Mix64(seed ^ Mix64(field ^ Mix64(static_cast<std::uint64_t>(i) ^ Mix64(static_cast<std::uint64_t>(j)))));
  const double u = static_cast<double>(h >> 11) * 0x1.0p-53;  // [0, 1)
  return static_cast<float>((2 * u - 1) * std::sqrt(3.0));
}

std::int64_t FloorDiv(std::int64_t a, std::int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

float Smooth(float t) { return t * t * (3 - 2 * t); }

// The patch of value noise with lattice spacing `scale` cells over global cells
// [ix0, ix0 + cols) x [iy0, iy0 + rows): lattice values smoothly interpolated, a function of the
// global index alone.
cv::Mat OctaveNoise(std::int64_t ix0, std::int64_t iy0, int cols, int rows, int scale, std::uint64_t seed,
                    std::uint64_t field) {
  cv::Mat out(rows, cols, CV_32F);
  const std::int64_t qx0 = FloorDiv(ix0, scale), qy0 = FloorDiv(iy0, scale);
  const int lat_cols = static_cast<int>(FloorDiv(ix0 + cols - 1, scale) - qx0) + 2;
  const int lat_rows = static_cast<int>(FloorDiv(iy0 + rows - 1, scale) - qy0) + 2;
  cv::Mat lattice(lat_rows, lat_cols, CV_32F);
  for (int j = 0; j < lat_rows; ++j) {
    for (int i = 0; i < lat_cols; ++i) lattice.at<float>(j, i) = LatticeValue(seed, field * 131 + static_cast<std::uint64_t>(scale), qx0 + i, qy0 + j);
  }
  for (int r = 0; r < rows; ++r) {
    const std::int64_t gy = iy0 + r, qy = FloorDiv(gy, scale);
    const float ay = Smooth(static_cast<float>(gy - qy * scale) / static_cast<float>(scale));
    const float* l0 = lattice.ptr<float>(static_cast<int>(qy - qy0));
    const float* l1 = lattice.ptr<float>(static_cast<int>(qy - qy0) + 1);
    auto* o = out.ptr<float>(r);
    for (int c = 0; c < cols; ++c) {
      const std::int64_t gx = ix0 + c, qx = FloorDiv(gx, scale);
      const int li = static_cast<int>(qx - qx0);
      const float ax = Smooth(static_cast<float>(gx - qx * scale) / static_cast<float>(scale));
      o[c] = (l0[li] * (1 - ax) + l0[li + 1] * ax) * (1 - ay) + (l1[li] * (1 - ax) + l1[li + 1] * ax) * ay;
    }
  }
  return out;
}

// The global cell window of a patch.
struct Window {
  std::int64_t ix0, iy0;
  int cols, rows;
};

cv::Mat Textured(const Window& w, const Look& look, std::uint64_t seed, std::uint64_t field) {
  cv::Mat albedo(w.rows, w.cols, CV_32F, cv::Scalar(look.albedo));
  const std::array<int, 3> scales{1, kMidScaleCells, kCoarseScaleCells};
  for (std::size_t k = 0; k < scales.size(); ++k) {
    if (look.amplitude[k] > 0) albedo += OctaveNoise(w.ix0, w.iy0, w.cols, w.rows, scales[k], seed, field) * look.amplitude[k];
  }
  return albedo;
}

Look GroundLook(TerrainKind kind) {
  switch (kind) {
    case TerrainKind::kGrass: return kGrassLook;
    case TerrainKind::kSoil: return kSoilLook;
    case TerrainKind::kGravel: return kGravelLook;
    case TerrainKind::kRubble: return kRubbleLook;
    case TerrainKind::kMixed: return kGrassLook;  // blended with rubble by GroundAlbedo
  }
  return kGrassLook;
}

cv::Mat GroundAlbedo(const WorldConfig& world, const Window& w, std::uint64_t seed) {
  const TerrainKind kind = world.terrain ? world.terrain->kind : TerrainKind::kGrass;
  cv::Mat albedo = Textured(w, GroundLook(kind), seed, kGroundSalt);
  if (kind != TerrainKind::kMixed) return albedo;
  cv::Mat rubble = Textured(w, kRubbleLook, seed, kGroundSalt);
  cv::Mat share = OctaveNoise(w.ix0, w.iy0, w.cols, w.rows, kMixScaleCells, seed, kMixSalt) * 0.5 + 0.5;
  cv::max(share, 0.0, share);
  cv::min(share, 1.0, share);
  cv::Mat grass_share = 1.0 - share;
  cv::multiply(albedo, grass_share, albedo);
  cv::Mat rubble_part;
  cv::multiply(rubble, share, rubble_part);
  return albedo + rubble_part;
}

// Calls visit(row, col, height, albedo) for each cell of the patch whose centre lies in the
// yaw-rotated footprint (centre, size x along yaw, size y across).
template <typename Visit>
void ForEachFootprintCell(StereoScene* s, const Window& w, const Vec3& centre, double size_x, double size_y, double yaw,
                          Visit visit) {
  const double c = std::cos(yaw), sn = std::sin(yaw);
  const double ex = (std::abs(c) * size_x + std::abs(sn) * size_y) / 2, ey = (std::abs(sn) * size_x + std::abs(c) * size_y) / 2;
  const double cell = s->cell_m;
  const int c0 = std::max(0, static_cast<int>(std::floor((centre.x - ex - s->origin_x_m) / cell)));
  const int c1 = std::min(w.cols - 1, static_cast<int>(std::ceil((centre.x + ex - s->origin_x_m) / cell)));
  const int r0 = std::max(0, static_cast<int>(std::floor((centre.y - ey - s->origin_y_m) / cell)));
  const int r1 = std::min(w.rows - 1, static_cast<int>(std::ceil((centre.y + ey - s->origin_y_m) / cell)));
  for (int r = r0; r <= r1; ++r) {
    auto* h = s->height_m.ptr<float>(r);
    auto* a = s->albedo.ptr<float>(r);
    const double dy = static_cast<double>(w.iy0 + r) * cell - centre.y;
    for (int col = c0; col <= c1; ++col) {
      const double dx = static_cast<double>(w.ix0 + col) * cell - centre.x;
      const double u = dx * c + dy * sn, v = -dx * sn + dy * c;
      if (std::abs(u) > size_x / 2 || std::abs(v) > size_y / 2) continue;
      visit(r, col, h[col], a[col]);
    }
  }
}

// Raises the cells of a yaw-rotated footprint (centre, size x along yaw, size y across) to top_m
// where that is higher, giving them the albedo of `texture` there.
void RaiseFootprint(StereoScene* s, const Window& w, const Vec3& centre, double size_x, double size_y, double yaw,
                    double top_m, const cv::Mat& texture) {
  const auto top = static_cast<float>(top_m);
  ForEachFootprintCell(s, w, centre, size_x, size_y, yaw, [&](int r, int col, float& h, float& a) {
    if (h > top) return;
    h = top;
    a = texture.at<float>(r, col);
  });
}

// The median height of the footprint's cells [m] (0 with none in the patch): what a body lying
// there rests on. The median, not the max: one brick under a shoulder does not lift the whole
// body, and a body half over a heap's edge lies at the level most of it rests on (the higher
// part of the heap then shows through it, as the footprint keeps higher cells).
double FootprintMedianHeight(StereoScene* s, const Window& w, const Vec3& centre, double size_x, double size_y,
                             double yaw) {
  std::vector<float> heights;
  ForEachFootprintCell(s, w, centre, size_x, size_y, yaw, [&](int, int, float& h, float&) { heights.push_back(h); });
  if (heights.empty()) return 0.0;
  const auto mid = heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 2);
  std::nth_element(heights.begin(), mid, heights.end());
  return *mid;
}

void AddObstacles(const WorldConfig& world, const Window& w, std::uint64_t seed, StereoScene* s) {
  if (world.obstacles.empty()) return;
  const cv::Mat box = Textured(w, kBoxLook, seed, kObstacleSalt);
  const cv::Mat tree = Textured(w, kTreeLook, seed, kObstacleSalt);
  for (const ObstacleBox& o : world.obstacles) {
    RaiseFootprint(s, w, o.center_m, o.size_m.x, o.size_m.y, o.yaw_rad, o.center_m.z + o.size_m.z / 2,
                   o.kind == ObstacleKind::kTree ? tree : box);
  }
}

void AddPeople(const WorldConfig& world, const Window& w, std::uint64_t seed, StereoScene* s) {
  if (world.victims.empty()) return;
  const cv::Mat person = Textured(w, kPersonLook, seed, kPersonSalt);
  for (const Victim& v : world.victims) {
    Vec3 centre;
    const Vec3 size = ApproxVictimBox(v, &centre);
    const double base_m = FootprintMedianHeight(s, w, centre, size.x, size.y, v.heading_rad);
    RaiseFootprint(s, w, centre, size.x, size.y, v.heading_rad, base_m + size.z, person);
  }
}

}  // namespace

double WorldAmbientWm2(const WorldConfig& world) {
  if (!world.lighting) return kSunInBandWm2;  // today's flat light: a clear noon
  // The camera's sun path (render_scene.cpp LightOf): up at 6 h, 60 deg at noon, down at 18 h.
  constexpr double kNoonElevation_rad = 60.0 * kPi / 180.0;
  const double day = (world.lighting->time_of_day_h - 6.0) / 12.0;
  const double elevation = kNoonElevation_rad * std::sin(kPi * day);
  const double sun = std::max(0.0, std::sin(elevation)) / std::sin(kNoonElevation_rad);
  const double twilight = std::clamp((elevation * 180.0 / kPi + 8.0) / 16.0, 0.05, 1.0);
  const double overcast = std::clamp(world.lighting->overcast, 0.0, 1.0);
  return kSunInBandWm2 * (kShadeFraction * twilight + (1 - kShadeFraction) * (1 - overcast) * sun);
}

Vec3 ApproxVictimBox(const Victim& v, Vec3* centre_m) {
  // The figures of render_scene.cpp PoseFigure, scaled by height / 1.75: extent along the
  // heading (from the feet), across it, and the top.
  const double s = v.height_m / 1.75;
  double along = v.height_m, across = kVictimWidth_m, offset = 0, top = kLyingVictimTop_m;
  switch (v.pose) {
    case VictimPose::kLying: break;
    case VictimPose::kSitting: along = 1.1 * s, across = 0.5 * s, offset = -0.3 * s, top = 0.95 * s; break;
    case VictimPose::kCurled: along = 0.95 * s, across = 0.65 * s, offset = 0.17 * s, top = 0.35 * s; break;
    case VictimPose::kStanding: along = 0.3 * s, across = 0.6 * s, offset = 0, top = v.height_m; break;
  }
  *centre_m = Vec3{v.x_m + offset * std::cos(v.heading_rad), v.y_m + offset * std::sin(v.heading_rad), 0};
  return Vec3{along, across, top};
}

SceneBox DroneBodyBox(const Airframe& airframe, const Pose& body, std::uint64_t texture_seed) {
  return {.centre_m = body.position_m + Rotate(body.attitude, airframe.collision_offset_m),
          .attitude = body.attitude,
          .half_size_m = airframe.collision_box_m * 0.5,
          .albedo = kDroneBodyAlbedo,
          .texture_seed = texture_seed};
}

SceneBox PayloadBox(const PayloadSpec& payload, const Pose& pose, std::uint64_t texture_seed) {
  return {.centre_m = pose.position_m,
          .attitude = pose.attitude,
          .half_size_m = payload.size_m * 0.5,
          .albedo = kPayloadAlbedo,
          .texture_seed = texture_seed};
}

StereoScene MakeWorldScene(const WorldConfig& world, double centre_x_m, double centre_y_m, double half_size_m,
                           std::uint64_t seed) {
  const double cell = kWorldSceneCell_m;
  const auto ix0 = static_cast<std::int64_t>(std::llround((centre_x_m - half_size_m) / cell));
  const auto iy0 = static_cast<std::int64_t>(std::llround((centre_y_m - half_size_m) / cell));
  const auto ix1 = static_cast<std::int64_t>(std::llround((centre_x_m + half_size_m) / cell));
  const auto iy1 = static_cast<std::int64_t>(std::llround((centre_y_m + half_size_m) / cell));
  const Window w{ix0, iy0, static_cast<int>(ix1 - ix0 + 1), static_cast<int>(iy1 - iy0 + 1)};
  StereoScene s;
  s.cell_m = cell;
  s.origin_x_m = static_cast<double>(ix0) * cell;
  s.origin_y_m = static_cast<double>(iy0) * cell;
  s.height_m = cv::Mat::zeros(w.rows, w.cols, CV_32F);
  s.albedo = GroundAlbedo(world, w, seed);
  AddObstacles(world, w, seed, &s);
  AddPeople(world, w, seed, &s);
  cv::max(s.albedo, kMinAlbedo, s.albedo);
  cv::min(s.albedo, kMaxAlbedo, s.albedo);
  s.ambient_w_m2 = cv::Mat(w.rows, w.cols, CV_32F, cv::Scalar(WorldAmbientWm2(world)));
  s.UpdateHeightRange();
  return s;
}

}  // namespace swarmbox::physics
