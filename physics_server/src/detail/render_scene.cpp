#include "detail/render_scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <string_view>

#include <opencv2/imgproc.hpp>

#include "detail/thermal_scene.hpp"
#include "swarmbox/physics/ground_renderer.hpp"

namespace swarmbox::physics::detail {
namespace {

constexpr double kPi = std::numbers::pi;

std::uint64_t Mix(std::uint64_t x) {  // splitmix64 finaliser
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

std::uint64_t HashOf(std::string_view s) {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a
  for (char c : s) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ULL;
  return Mix(h);
}

cv::Scalar S(const Bgr& c) { return cv::Scalar(c[0], c[1], c[2]); }
cv::Scalar Scale(const cv::Scalar& c, double k) { return cv::Scalar(c[0] * k, c[1] * k, c[2] * k); }

// Local (u along heading, v to its left, z up) -> world.
struct Frame2 {
  double x, y, ch, sh;
  Vec3 operator()(double u, double v, double z) const { return {x + u * ch - v * sh, y + u * sh + v * ch, z}; }
};

std::vector<Vec3> Ring(const Frame2& f, double u, double v, double a, double b, double z, int n = 16) {
  std::vector<Vec3> pts;
  pts.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double t = 2 * kPi * i / n;
    pts.push_back(f(u + a * std::cos(t), v + b * std::sin(t), z));
  }
  return pts;
}

// A limb: the hull of two rings (a capsule once projected).
std::vector<Vec3> Capsule(const Frame2& f, const Vec3& p, const Vec3& q, double r) {
  std::vector<Vec3> pts = Ring(f, p.x, p.y, r, r, p.z, 10);
  const std::vector<Vec3> b = Ring(f, q.x, q.y, r, r, q.z, 10);
  pts.insert(pts.end(), b.begin(), b.end());
  return pts;
}

std::vector<Vec3> Concat(std::vector<Vec3> a, const std::vector<Vec3>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// An irregular convex-ish blob: n vertices at random radii in [r*(1-jag), r].
std::vector<Vec3> Blob(const Frame2& f, double u, double v, double r, double z, double jag, cv::RNG& rng, int n = 9) {
  std::vector<Vec3> pts;
  const double phase = rng.uniform(0.0, 2 * kPi);
  for (int i = 0; i < n; ++i) {
    const double t = phase + 2 * kPi * i / n;
    const double rr = r * (1 - jag * rng.uniform(0.0, 1.0));
    pts.push_back(f(u + rr * std::cos(t), v + rr * std::sin(t), z));
  }
  return pts;
}

// ---- people ----------------------------------------------------------------------------------

constexpr std::array<Bgr, 5> kSkin = {{{130, 160, 215}, {105, 140, 190}, {80, 110, 160}, {55, 75, 115}, {120, 150, 200}}};
constexpr std::array<Bgr, 4> kHair = {{{20, 25, 30}, {30, 50, 80}, {70, 110, 150}, {40, 40, 45}}};
constexpr std::array<Bgr, 5> kTrousers = {{{95, 65, 45}, {40, 50, 60}, {55, 55, 55}, {80, 100, 95}, {30, 35, 40}}};

// A part's colour and how it warms.
struct Paint {
  cv::Scalar colour;
  Heat heat = Heat::kSolid;
};

// Adds a figure's parts in the victim's frame `f`, at `s` times the size of a 1.75 m person.
struct FigureBuilder {
  Frame2 f;
  double s;
  std::vector<Part>* parts;
  void Limb(Vec3 p, Vec3 q, double r, const Paint& c) const {
    parts->push_back(
        {Capsule(f, {p.x * s, p.y * s, p.z * s}, {q.x * s, q.y * s, q.z * s}, r * s), c.colour, c.heat});
  }
  void Disc(double u, double w, double a, double b, double z, const Paint& c) const {
    parts->push_back({Ring(f, u * s, w * s, a * s, b * s, z * s), c.colour, c.heat});
  }
  // An upright trunk: a ring at z0 under one at z1 (sitting and standing).
  void Trunk(double u1, double a0, double b0, double z0, double a1, double b1, double z1,
             const Paint& c) const {
    parts->push_back(
        {Concat(Ring(f, 0, 0, a0 * s, b0 * s, z0 * s), Ring(f, u1 * s, 0, a1 * s, b1 * s, z1 * s)), c.colour,
         c.heat});
  }
};

struct FigureColours {
  Paint cloth, legs, skin, hair;
};

void PoseFigure(VictimPose pose, const FigureBuilder& b, const FigureColours& c, double arm_swing) {
  switch (pose) {
    case VictimPose::kLying:
      b.Limb({-0.85, 0.10, 0.04}, {-0.05, 0.10, 0.06}, 0.085, c.legs);
      b.Limb({-0.85, -0.10, 0.04}, {-0.05, -0.10, 0.06}, 0.085, c.legs);
      b.Disc(0.25, 0, 0.33, 0.21, 0.1, c.cloth);
      b.Limb({0.50, 0.25, 0.08}, {0.02 + 2 * arm_swing, 0.30 - 0.15 * arm_swing, 0.05}, 0.055, c.cloth);
      b.Limb({0.50, -0.25, 0.08}, {0.02, -0.30, 0.05}, 0.055, c.cloth);
      b.Disc(0.75, 0, 0.115, 0.095, 0.12, c.skin);
      b.Disc(0.80, 0, 0.085, 0.085, 0.14, c.hair);
      return;
    case VictimPose::kSitting:
      b.Limb({-0.85, 0.10, 0.05}, {0.0, 0.10, 0.12}, 0.085, c.legs);
      b.Limb({-0.85, -0.10, 0.05}, {0.0, -0.10, 0.12}, 0.085, c.legs);
      b.Trunk(0.06, 0.14, 0.19, 0.12, 0.12, 0.22, 0.6, c.cloth);
      b.Limb({0.06, 0.24, 0.55}, {-0.35, 0.20, 0.22}, 0.055, c.cloth);
      b.Limb({0.06, -0.24, 0.55}, {-0.35, -0.20, 0.22}, 0.055, c.cloth);
      b.Disc(0.08, 0, 0.1, 0.09, 0.82, c.skin);
      b.Disc(0.11, 0, 0.08, 0.08, 0.88, c.hair);
      return;
    case VictimPose::kCurled:
      b.Disc(0.15, 0, 0.30, 0.18, 0.15, c.cloth);
      b.Limb({-0.10, 0.0, 0.12}, {0.05, -0.35, 0.12}, 0.09, c.legs);
      b.Limb({0.05, -0.35, 0.10}, {-0.30, -0.38, 0.06}, 0.07, c.legs);
      b.Limb({0.35, 0.05, 0.18}, {0.20, -0.25, 0.12}, 0.055, c.cloth);
      b.Disc(0.55, -0.05, 0.11, 0.095, 0.15, c.skin);
      b.Disc(0.59, -0.05, 0.08, 0.08, 0.17, c.hair);
      return;
    case VictimPose::kStanding:
      b.Limb({0.0, 0.10, 0.0}, {0.0, 0.10, 0.9}, 0.08, c.legs);
      b.Limb({0.0, -0.10, 0.0}, {0.0, -0.10, 0.9}, 0.08, c.legs);
      b.Trunk(0, 0.12, 0.18, 0.9, 0.12, 0.23, 1.45, c.cloth);
      b.Limb({0.0, 0.26, 1.42}, {0.05, 0.30, 0.82}, 0.05, c.cloth);
      b.Limb({0.0, -0.26, 1.42}, {0.05, -0.30, 0.82}, 0.05, c.cloth);
      b.Disc(0.0, 0, 0.1, 0.09, 1.62, c.skin);
      b.Disc(-0.02, 0, 0.085, 0.08, 1.7, c.hair);
      return;
  }
}

std::vector<Part> FigureParts(const Victim& v) {
  const Frame2 f{v.x_m, v.y_m, std::cos(v.heading_rad), std::sin(v.heading_rad)};
  if (!v.clothing_bgr && v.pose == VictimPose::kLying) {
    // Today's figure: hi-vis orange body ellipse 1.44 x 0.48 m, amber head.
    return {{Ring(f, -0.15, 0, 0.72, 0.24, 0.0, 20),
             cv::Scalar(kVictimBodyBgr[0], kVictimBodyBgr[1], kVictimBodyBgr[2]), Heat::kClothing},
            {Ring(f, 0.7, 0, 0.13, 0.11, 0.0, 20),
             cv::Scalar(kVictimHeadBgr[0], kVictimHeadBgr[1], kVictimHeadBgr[2]), Heat::kSkin}};
  }
  const std::uint64_t h = HashOf(v.id);
  FigureColours c;
  c.cloth = {v.clothing_bgr ? S(*v.clothing_bgr)
                            : cv::Scalar(kVictimBodyBgr[0], kVictimBodyBgr[1], kVictimBodyBgr[2]),
             Heat::kClothing};
  c.legs = {((h >> 8) % 4 == 0) ? Scale(c.cloth.colour, 0.85) : S(kTrousers[(h >> 12) % kTrousers.size()]),
            Heat::kClothing};
  c.skin = {S(kSkin[(h >> 16) % kSkin.size()]), Heat::kSkin};
  c.hair = {S(kHair[(h >> 20) % kHair.size()]), Heat::kHair};
  std::vector<Part> parts;
  const double arm_swing = ((h >> 24) % 3 == 0) ? 0.45 : 0.0;  // one arm above the head, sometimes
  PoseFigure(v.pose, FigureBuilder{f, v.height_m / 1.75, &parts}, c, arm_swing);
  return parts;
}

// Cover: blobs of debris or foliage laid over the figure until `cover` of its plan area (measured
// on a 2 cm raster) is hidden.
// The plan raster of CoverParts: 2 cm cells over +-1.2 m around the victim.
struct CoverRaster {
  static constexpr double kRes = 0.02;  // m per raster cell
  static constexpr int kHalf = 60;      // raster spans +-1.2 m around the victim
  double x_m, y_m;                      // the victim

  cv::Point Cell(const Vec3& p) const {
    return cv::Point(static_cast<int>(std::lround((p.x - x_m) / kRes)) + kHalf, static_cast<int>(std::lround((p.y - y_m) / kRes)) + kHalf);
  }
  // The convex hull of pts, filled into mask.
  void Fill(const std::vector<Vec3>& pts, cv::Mat& mask) const {
    std::vector<cv::Point> poly, hull;
    for (const Vec3& p : pts) poly.push_back(Cell(p));
    cv::convexHull(poly, hull);
    cv::fillConvexPoly(mask, hull, cv::Scalar(255));
  }
};

// A blob of cover's colour: foliage, or concrete, brick, soil and wood.
cv::Scalar CoverColour(bool vegetation, cv::RNG& rng) {
  if (vegetation) return cv::Scalar(rng.uniform(25, 50), rng.uniform(75, 125), rng.uniform(35, 70));
  const int kind = rng.uniform(0, 3);
  return kind == 0 ? cv::Scalar(rng.uniform(120, 160), rng.uniform(125, 165), rng.uniform(130, 170))   // concrete
         : kind == 1 ? cv::Scalar(rng.uniform(50, 75), rng.uniform(65, 95), rng.uniform(120, 160))   // brick
                     : cv::Scalar(rng.uniform(45, 70), rng.uniform(70, 95), rng.uniform(90, 120));   // soil, wood
}

// Cover: blobs of debris or foliage laid over the figure until `cover` of its plan area (measured
// on a 2 cm raster) is hidden.
std::vector<Part> CoverParts(const Victim& v, const std::vector<Part>& figure, bool vegetation, std::uint64_t seed) {
  std::vector<Part> out;
  if (v.cover <= 0) return out;
  const CoverRaster raster{v.x_m, v.y_m};
  constexpr int kHalf = CoverRaster::kHalf;
  cv::Mat fig(2 * kHalf, 2 * kHalf, CV_8U, cv::Scalar(0)), hidden(fig.size(), CV_8U, cv::Scalar(0));
  for (const Part& part : figure) raster.Fill(part.pts, fig);
  std::vector<cv::Point> cells;
  cv::findNonZero(fig, cells);
  if (cells.empty()) return out;
  const double total = static_cast<double>(cells.size());
  cv::RNG rng(seed);
  const double top_z = v.pose == VictimPose::kStanding ? 0.7 : v.pose == VictimPose::kSitting ? 0.5 : 0.25;
  const Frame2 world{0, 0, 1, 0};
  for (int k = 0; k < 80; ++k) {
    cv::Mat both;
    cv::bitwise_and(fig, hidden, both);
    if (cv::countNonZero(both) >= v.cover * total) break;
    const cv::Point c = cells[static_cast<std::size_t>(rng.uniform(0, static_cast<int>(cells.size())))];
    const double x = (c.x - kHalf) * CoverRaster::kRes + v.x_m, y = (c.y - kHalf) * CoverRaster::kRes + v.y_m;
    const double r = rng.uniform(0.15, 0.32);
    const cv::Scalar colour = CoverColour(vegetation, rng);
    std::vector<Vec3> pts = Blob(world, x, y, r, top_z, 0.45, rng);
    raster.Fill(pts, hidden);
    out.push_back({std::move(pts), colour, vegetation ? Heat::kVegetation : Heat::kSolid});
  }
  return out;
}

// ---- distractors, trees, boxes --------------------------------------------------------------

// A flat quad (u0, v0)-(u1, v1) in the frame at height z.
std::vector<Vec3> Quad(const Frame2& f, double u0, double v0, double u1, double v1, double z) {
  return std::vector<Vec3>{f(u0, v0, z), f(u1, v0, z), f(u1, v1, z), f(u0, v1, z)};
}

// One distractor's parts and height: what DistractorDrawable draws of its kind (size s, colour c;
// the random folds, planks and blobs from rng).
struct DistractorShape {
  const Frame2& f;
  double s;
  cv::Scalar c;
  cv::RNG& rng;
  Drawable* out;

  void Tarp() const {
    const double a = s / 2, b = 0.375 * s;
    out->parts.push_back({Quad(f, -a, -b, a, b, 0.02), c, Heat::kSheet});
    const double fold = rng.uniform(-0.3, 0.3) * s;  // a fold: one side in its own shade
    out->parts.push_back(
        {{f(fold - 0.1 * s, -b, 0.03), f(a, -b, 0.03), f(a, b, 0.03), f(fold + 0.1 * s, b, 0.03)},
         Scale(c, 0.8),
         Heat::kSheet});
    out->top_m = 0.05;
  }
  void Cone() const {
    const double r = s / 2, hgt = 1.4 * s;
    out->parts.push_back({Concat(Ring(f, 0, 0, r, r, 0), {f(0, 0, hgt)}), c, Heat::kSheet});
    out->parts.push_back(
        {Concat(Ring(f, 0, 0, 0.55 * r, 0.55 * r, 0.45 * hgt), Ring(f, 0, 0, 0.42 * r, 0.42 * r, 0.6 * hgt)),
         cv::Scalar(225, 230, 230), Heat::kSheet});
    out->parts.push_back(
        {Concat(Ring(f, 0, 0, 0.3 * r, 0.3 * r, 0.7 * hgt), {f(0, 0, hgt)}), c, Heat::kSheet});
    out->top_m = hgt;
  }
  void Backpack() const {
    const double a = s / 2, b = 0.33 * s, hgt = 0.4 * s;
    out->parts.push_back(
        {Concat(Quad(f, -a, -b, a, b, 0), Quad(f, -a, -b, a, b, hgt)), Scale(c, 0.7), Heat::kSheet});
    out->parts.push_back({Quad(f, -a * 0.95, -b * 0.95, a * 0.95, b * 0.95, hgt), c, Heat::kSheet});
    out->parts.push_back({Quad(f, a * 0.25, -b * 0.9, a * 0.95, b * 0.9, hgt + 0.01), Scale(c, 0.6),
                          Heat::kSheet});  // the flap
    out->top_m = hgt;
  }
  void Debris() const {
    if (rng.uniform(0, 2) == 0) {  // a plank
      const double a = s / 2, b = 0.12 * s;
      out->parts.push_back({Quad(f, -a, -b, a, b, 0.05), c});
      out->parts.push_back({Quad(f, -a, -b * 0.2, a, b * 0.2, 0.06), Scale(c, 0.75)});
    } else {  // a broken sheet
      out->parts.push_back({Blob(f, 0, 0, s / 2, 0.05, 0.5, rng, 7), c, Heat::kSheet});
    }
    out->top_m = 0.06;
  }
  void Rock() const {
    const double r = s / 2;
    out->parts.push_back({Blob(f, 0, 0, r, 0, 0.3, rng, 9), Scale(c, 0.75)});
    out->parts.push_back({Blob(f, -0.1 * r, 0.1 * r, 0.75 * r, 0.45 * r, 0.3, rng, 9), c});
    out->top_m = 0.45 * r;
  }
};

Drawable DistractorDrawable(const Distractor& d, std::uint64_t seed) {
  const Frame2 f{d.x_m, d.y_m, std::cos(d.heading_rad), std::sin(d.heading_rad)};
  cv::RNG rng(seed);
  Drawable out;
  out.centre_m = {d.x_m, d.y_m, 0};
  out.radius_m = d.size_m;
  out.hides_people = false;
  const DistractorShape shape{f, d.size_m, S(d.colour_bgr), rng, &out};
  switch (d.kind) {
    case DistractorKind::kTarp: shape.Tarp(); break;
    case DistractorKind::kCone: shape.Cone(); break;
    case DistractorKind::kBackpack: shape.Backpack(); break;
    case DistractorKind::kDebris: shape.Debris(); break;
    case DistractorKind::kRock: shape.Rock(); break;
  }
  return out;
}

Drawable TreeDrawable(const ObstacleBox& b, std::uint64_t seed, const Light& light) {
  cv::RNG rng(seed);
  const double r = std::min(b.size_m.x, b.size_m.y) / 2;
  const double top = b.center_m.z + b.size_m.z / 2;
  const double crown_bottom = std::max(b.center_m.z - b.size_m.z / 2 + 0.4 * b.size_m.z, top - 2.2 * r);
  const Frame2 f{b.center_m.x, b.center_m.y, 1, 0};
  const cv::Scalar leaf(rng.uniform(28, 45), rng.uniform(70, 105), rng.uniform(30, 55));
  Drawable out;
  out.centre_m = {b.center_m.x, b.center_m.y, 0};
  out.radius_m = r;
  out.top_m = top;
  out.parts.push_back({Capsule(f, {0, 0, 0}, {0, 0, crown_bottom}, std::max(0.12, 0.08 * r)), cv::Scalar(35, 55, 75)});
  out.parts.push_back({Concat(Blob(f, 0, 0, r * 0.85, crown_bottom, 0.15, rng, 12),
                              Blob(f, 0, 0, r, top - 0.3 * (top - crown_bottom), 0.2, rng, 12)),
                       Scale(leaf, 0.85), Heat::kVegetation});
  // Clumps of foliage, lit on the sun's side.
  const double sun_u = light.enabled ? light.to_sun.x : 0, sun_v = light.enabled ? light.to_sun.y : 0;
  for (int k = 0; k < 5; ++k) {
    const double a = rng.uniform(0.0, 2 * kPi), d = rng.uniform(0.0, 0.55 * r);
    const double u = d * std::cos(a) + 0.2 * r * sun_u, v = d * std::sin(a) + 0.2 * r * sun_v;
    out.parts.push_back(
        {Blob(f, u, v, r * rng.uniform(0.3, 0.45), top - 0.1 * (top - crown_bottom), 0.3, rng, 8),
         Scale(leaf, rng.uniform(1.0, 1.3)), Heat::kVegetation});
  }
  return out;
}

Drawable BoxDrawable(const ObstacleBox& b) {
  const double cy = std::cos(b.yaw_rad), sy = std::sin(b.yaw_rad);
  std::vector<Vec3> all, top;
  for (int i = 0; i < 8; ++i) {
    const double dx = ((i & 1) ? 0.5 : -0.5) * b.size_m.x;
    const double dy = ((i & 2) ? 0.5 : -0.5) * b.size_m.y;
    const double dz = ((i & 4) ? 0.5 : -0.5) * b.size_m.z;
    const Vec3 p{b.center_m.x + dx * cy - dy * sy, b.center_m.y + dx * sy + dy * cy, b.center_m.z + dz};
    all.push_back(p);
    if (i & 4) top.push_back(p);
  }
  Drawable out;
  out.is_box = true;
  out.parts = {{std::move(all), cv::Scalar(70, 75, 80)}, {std::move(top), cv::Scalar(150, 155, 160)}};
  out.top_m = b.center_m.z + b.size_m.z / 2;
  out.centre_m = {b.center_m.x, b.center_m.y, 0};
  out.radius_m = std::hypot(b.size_m.x, b.size_m.y) / 2 + b.size_m.z;
  return out;
}

// ---- ground texture -------------------------------------------------------------------------

// Sum of value-noise octaves, each a random grid upsampled smoothly.
cv::Mat Noise(cv::RNG& rng, cv::Size size, std::initializer_list<std::pair<int, float>> octaves) {
  cv::Mat acc(size, CV_32F, cv::Scalar(0));
  for (const auto& [cells, weight] : octaves) {
    cv::Mat grid(std::max(2, cells * size.height / size.width), std::max(2, cells), CV_32F);
    rng.fill(grid, cv::RNG::UNIFORM, 0.0, 1.0);
    cv::Mat up;
    cv::resize(grid, up, size, 0, 0, cv::INTER_CUBIC);
    acc += up * weight;
  }
  return acc;
}

// Today's look: grass with soil patches (the RNG sequence is the original one).
void LegacyTexture(const WorldConfig& config, cv::Mat* texture, cv::Mat* vegetation) {
  const int rows = texture->rows, cols = texture->cols;
  cv::RNG rng(config.ground_texture_seed * 0x9E3779B97F4A7C15ULL + 1);
  cv::Mat acc(rows, cols, CV_32F, cv::Scalar(0));
  cv::Mat soil(rows, cols, CV_32F);
  const std::array<std::pair<int, float>, 4> octaves = {{{8, 0.35f}, {24, 0.3f}, {96, 0.2f}, {400, 0.15f}}};
  for (const auto& [cells, weight] : octaves) {
    cv::Mat grid(std::max(2, cells * rows / cols), cells, CV_32F);
    rng.fill(grid, cv::RNG::UNIFORM, 0.0, 1.0);
    cv::Mat up;
    cv::resize(grid, up, acc.size(), 0, 0, cv::INTER_CUBIC);
    acc += up * weight;
  }
  {
    cv::Mat grid(6, 6, CV_32F);
    rng.fill(grid, cv::RNG::UNIFORM, 0.0, 1.0);
    cv::resize(grid, soil, acc.size(), 0, 0, cv::INTER_CUBIC);
  }
  cv::Mat grain(rows, cols, CV_32F);
  rng.fill(grain, cv::RNG::NORMAL, 0.0, 0.06);
  acc += grain;
  for (int r = 0; r < rows; ++r) {
    const float* a = acc.ptr<float>(r);
    const float* s = soil.ptr<float>(r);
    auto* px = texture->ptr<cv::Vec3b>(r);
    auto* veg = vegetation->ptr<std::uint8_t>(r);
    for (int c = 0; c < cols; ++c) {
      const float v = std::clamp(a[c], 0.0f, 1.2f);
      const float soil_mix = std::clamp((s[c] - 0.62f) * 4.0f, 0.0f, 1.0f);
      veg[c] = cv::saturate_cast<std::uint8_t>(255 * (1 - soil_mix));
      const float gb = 30 + 40 * v, gg = 80 + 70 * v, gr = 40 + 50 * v;
      const float sb = 50 + 30 * v, sg = 70 + 30 * v, sr = 90 + 30 * v;
      px[c] = cv::Vec3b(cv::saturate_cast<std::uint8_t>(gb + (sb - gb) * soil_mix),
                        cv::saturate_cast<std::uint8_t>(gg + (sg - gg) * soil_mix),
                        cv::saturate_cast<std::uint8_t>(gr + (sr - gr) * soil_mix));
    }
  }
}

struct Palette {
  cv::Vec3f lo, hi;  // colour at noise 0 and 1 (BGR)
  float grain;       // per-texel speckle (std, levels)
};
const Palette kGrassP{{30, 85, 45}, {60, 150, 95}, 10};
const Palette kDryGrassP{{55, 120, 130}, {85, 160, 170}, 10};
const Palette kSoilP{{35, 55, 75}, {85, 110, 140}, 14};
const Palette kGravelP{{120, 130, 135}, {165, 170, 175}, 22};
const Palette kRubbleP{{95, 100, 105}, {145, 150, 155}, 18};

cv::Vec3f Lerp(const Palette& p, float t) { return p.lo + (p.hi - p.lo) * t; }

constexpr float kWaterEdge = 0.012f;  // muddy band above the water level

// The level under which the smooth field `water` is water: its lowest water_fraction, after
// raising it 4 m around every victim (drawn into *water) so that nobody lies in water; -1: none.
float WaterLevel(const WorldConfig& config, const Terrain& terrain, double texel_m, double origin_x_m,
                 double top_y_m, cv::Mat* water) {
  if (!(terrain.water_fraction > 0)) return -1;
  for (const Victim& v : config.victims) {
    const cv::Point c(static_cast<int>((v.x_m - origin_x_m) / texel_m), static_cast<int>((top_y_m - v.y_m) / texel_m));
    cv::circle(*water, c, static_cast<int>(4.0 / texel_m), cv::Scalar(2.0), cv::FILLED);
  }
  cv::Mat sample;
  cv::resize(*water, sample, cv::Size(256, 256), 0, 0, cv::INTER_NEAREST);
  std::vector<float> values(sample.begin<float>(), sample.end<float>());
  std::nth_element(values.begin(), values.begin() + static_cast<long>(terrain.water_fraction * double(values.size())), values.end());
  return values[static_cast<std::size_t>(terrain.water_fraction * double(values.size()))];
}

// One texel's ground colour for brightness noise `v` and the region noises `g`, `g2`; its speckle
// in *grain_std, its share of living vegetation in *veg (dry grass counts half: it transpires less).
cv::Vec3f GroundColour(TerrainKind kind, float v, float g, float g2, float* grain_std, float* veg) {
  const float dry = std::clamp((g2 - 0.55f) * 5.0f, 0.0f, 1.0f);
  auto grass = [&] { return Lerp(kGrassP, v) * (1 - dry) + Lerp(kDryGrassP, v) * dry; };
  const float grass_veg = 1 - 0.5f * dry;
  *veg = 0;
  switch (kind) {
    case TerrainKind::kGrass:
      *grain_std = kGrassP.grain;
      *veg = grass_veg;
      return grass();
    case TerrainKind::kSoil: {
      const float grassy = std::clamp((g - 0.7f) * 5.0f, 0.0f, 1.0f);
      *grain_std = kSoilP.grain;
      *veg = grass_veg * grassy;
      return Lerp(kSoilP, v) * (1 - grassy) + grass() * grassy;
    }
    case TerrainKind::kGravel:
      *grain_std = kGravelP.grain;
      return Lerp(kGravelP, v);
    case TerrainKind::kRubble: {
      const float dirt = std::clamp((g - 0.5f) * 4.0f, 0.0f, 1.0f);
      *grain_std = kRubbleP.grain;
      return Lerp(kRubbleP, v) * (1 - dirt) + Lerp(kSoilP, v) * dirt;
    }
    case TerrainKind::kMixed:
      if (g < 0.45f) {
        *grain_std = kGrassP.grain;
        *veg = grass_veg;
        return grass();
      }
      if (g < 0.62f) {
        *grain_std = kSoilP.grain;
        return Lerp(kSoilP, v);
      }
      *grain_std = kGravelP.grain;
      return Lerp(kGravelP, v);
  }
  *grain_std = 0;
  return cv::Vec3f();
}

// Water below the level (deeper, darker), mud in a band above it; `col` elsewhere. *wet: 1 in
// the water, falling from 0.5 at the waterline to 0 across the mud; 0 elsewhere.
cv::Vec3f WithWater(const cv::Vec3f& col, float w, float water_level, float n, float* wet) {
  *wet = 0;
  if (w < water_level) {
    const float depth = std::clamp((water_level - w) * 12.0f, 0.0f, 1.0f);
    *wet = 1;
    return cv::Vec3f(70, 75, 50) * (1 - depth) + cv::Vec3f(85, 70, 35) * depth + cv::Vec3f(1, 1, 1) * (3 * n);
  }
  if (w < water_level + kWaterEdge) {
    const float t = (w - water_level) / kWaterEdge;  // mud at the waterline, drying outwards
    *wet = 0.5f * (1 - t);
    return cv::Vec3f(40, 55, 65) * (1 - t) + col * t;
  }
  return col;
}

// Chunks of concrete and brick scattered over the ground (rubble everywhere, gravel areas of
// mixed), never in the water or its muddy band.
void ScatterRubble(const Terrain& terrain, double texel_m, const cv::Mat& region, const cv::Mat& water,
                   float water_level, cv::RNG& rng, cv::Mat* texture, cv::Mat* vegetation) {
  const cv::Size size = texture->size();
  const double area = (size.width * texel_m) * (size.height * texel_m);
  const int count = static_cast<int>(area * (terrain.kind == TerrainKind::kRubble ? 0.6 : 0.1));
  for (int k = 0; k < count; ++k) {
    const cv::Point2d c(rng.uniform(0.0, double(size.width)), rng.uniform(0.0, double(size.height)));
    if (terrain.kind == TerrainKind::kMixed && region.at<float>(static_cast<int>(c.y), static_cast<int>(c.x)) < 0.62f) continue;
    if (water.at<float>(static_cast<int>(c.y), static_cast<int>(c.x)) < water_level + kWaterEdge) continue;
    const double rr = rng.uniform(0.1, 0.45) / texel_m;
    std::vector<cv::Point> pts;
    const int n = 5 + rng.uniform(0, 3);
    const double ph = rng.uniform(0.0, 2 * kPi);
    for (int i = 0; i < n; ++i) {
      const double t = ph + 2 * kPi * i / n, q = rr * rng.uniform(0.55, 1.0);
      pts.emplace_back(static_cast<int>((c.x + q * std::cos(t)) * 16), static_cast<int>((c.y + q * std::sin(t)) * 16));
    }
    const int kind = rng.uniform(0, 4);
    const cv::Scalar col = kind == 0 ? cv::Scalar(rng.uniform(60, 80), rng.uniform(75, 100), rng.uniform(125, 165))
                           : kind == 3 ? cv::Scalar(55, 60, 65)
                                       : cv::Scalar::all(rng.uniform(125, 185)) + cv::Scalar(0, 3, 6);
    std::vector<cv::Point> hull;
    cv::convexHull(pts, hull);
    cv::fillConvexPoly(*texture, hull, col, cv::LINE_8, 4);
    cv::fillConvexPoly(*vegetation, hull, cv::Scalar(0), cv::LINE_8, 4);
  }
}

void TerrainTexture(const WorldConfig& config, const Terrain& terrain, double texel_m, double origin_x_m,
                    double top_y_m, cv::Mat* texture, cv::Mat* vegetation, cv::Mat* wet) {
  const cv::Size size = texture->size();
  cv::RNG rng(Mix(config.ground_texture_seed ^ 0x7E44A1ULL));
  const cv::Mat base = Noise(rng, size, {{8, 0.35f}, {24, 0.3f}, {96, 0.2f}, {400, 0.15f}});
  const cv::Mat region = Noise(rng, size, {{5, 0.6f}, {14, 0.4f}});    // which cover where (mixed, dry grass)
  const cv::Mat region2 = Noise(rng, size, {{7, 0.6f}, {20, 0.4f}});
  cv::Mat water = Noise(rng, size, {{4, 0.55f}, {12, 0.3f}, {40, 0.15f}});
  cv::Mat grain(size, CV_32F);
  rng.fill(grain, cv::RNG::NORMAL, 0.0, 1.0);
  const float water_level = WaterLevel(config, terrain, texel_m, origin_x_m, top_y_m, &water);
  for (int r = 0; r < size.height; ++r) {
    const float* a = base.ptr<float>(r);
    const float* g = region.ptr<float>(r);
    const float* g2 = region2.ptr<float>(r);
    const float* w = water.ptr<float>(r);
    const float* n = grain.ptr<float>(r);
    auto* px = texture->ptr<cv::Vec3b>(r);
    auto* veg_px = vegetation->ptr<std::uint8_t>(r);
    auto* wet_px = wet->ptr<std::uint8_t>(r);
    for (int c = 0; c < size.width; ++c) {
      const float v = std::clamp(a[c], 0.0f, 1.2f) / 1.2f;
      float grain_std = 0, veg = 0, wetness = 0;
      cv::Vec3f col = GroundColour(terrain.kind, v, g[c], g2[c], &grain_std, &veg);
      col += cv::Vec3f(1, 1, 1) * (grain_std * n[c]);
      col = WithWater(col, w[c], water_level, n[c], &wetness);
      veg_px[c] = cv::saturate_cast<std::uint8_t>(255 * veg * (1 - std::min(1.0f, 2 * wetness)));
      wet_px[c] = cv::saturate_cast<std::uint8_t>(255 * wetness);
      px[c] = cv::Vec3b(cv::saturate_cast<std::uint8_t>(col[0]), cv::saturate_cast<std::uint8_t>(col[1]),
                        cv::saturate_cast<std::uint8_t>(col[2]));
    }
  }
  if (terrain.kind == TerrainKind::kRubble || terrain.kind == TerrainKind::kMixed) {
    ScatterRubble(terrain, texel_m, region, water, water_level, rng, texture, vegetation);
  }
}

// Darkens the texture where the parts' shadows fall (each part's points projected along the sun);
// *shadow (zeros, the texture's size) receives the mask, 255 in full shadow.
void BakeShadows(const std::vector<const std::vector<Part>*>& casters, const Light& light, double texel_m,
                 double origin_x_m, double top_y_m, cv::Mat* texture, cv::Mat* shadow) {
  if (!light.enabled || light.shadow_factor >= 0.99 || light.to_sun.z <= 0.05) return;
  cv::Mat& mask = *shadow;
  const double kx = light.to_sun.x / light.to_sun.z, ky = light.to_sun.y / light.to_sun.z;
  for (const std::vector<Part>* parts : casters) {
    for (const Part& part : *parts) {
      std::vector<cv::Point> pts, hull;
      for (const Vec3& p : part.pts) {
        for (double z : {0.0, p.z}) {  // the part's foot and its shadow
          const double x = p.x - kx * z, y = p.y - ky * z;
          pts.emplace_back(static_cast<int>((x - origin_x_m) / texel_m * 16), static_cast<int>((top_y_m - y) / texel_m * 16));
        }
      }
      cv::convexHull(pts, hull);
      cv::fillConvexPoly(mask, hull, cv::Scalar(255), cv::LINE_8, 4);
    }
  }
  cv::GaussianBlur(mask, mask, cv::Size(3, 3), 0);
  const float dark = static_cast<float>(1 - light.shadow_factor) / 255.0f;
  for (int r = 0; r < texture->rows; ++r) {
    const std::uint8_t* m = mask.ptr<std::uint8_t>(r);
    auto* px = texture->ptr<cv::Vec3b>(r);
    for (int c = 0; c < texture->cols; ++c) {
      if (m[c] == 0) continue;
      const float k = 1 - dark * m[c];
      px[c] = cv::Vec3b(cv::saturate_cast<std::uint8_t>(px[c][0] * k), cv::saturate_cast<std::uint8_t>(px[c][1] * k),
                        cv::saturate_cast<std::uint8_t>(px[c][2] * k));
    }
  }
}

}  // namespace

Light LightOf(const WorldConfig& config) {
  Light l;
  if (!config.lighting) return l;
  const Lighting& in = *config.lighting;
  l.enabled = true;
  // Sun: rises in the east at 6 h, south (elevation 60 deg) at noon, sets in the west at 18 h.
  const double day = (in.time_of_day_h - 6.0) / 12.0;
  const double elevation = (60.0 * kPi / 180.0) * std::sin(kPi * day);
  const double azimuth = kPi / 2 + kPi * day;  // from north, clockwise
  l.to_sun = {std::cos(elevation) * std::sin(azimuth), std::cos(elevation) * std::cos(azimuth), std::sin(elevation)};
  const double sun = std::max(0.0, std::sin(elevation));
  const double twilight = std::clamp((elevation * 180.0 / kPi + 8.0) / 16.0, 0.05, 1.0);
  const double direct = sun * (1.0 - 0.85 * in.overcast);
  const double ambient = (0.3 + 0.25 * in.overcast) * twilight;
  constexpr double kNoonClear = 0.3 + 0.8660254;  // ambient + direct at noon, clear sky
  l.level = (ambient + direct) / kNoonClear;
  l.shadow_factor = ambient / std::max(1e-6, ambient + direct);
  l.direct = direct;
  l.ambient = ambient;
  const double warm = (1.0 - std::clamp(sun / 0.5, 0.0, 1.0)) * (1.0 - in.overcast);  // low sun: warm light
  l.colour = cv::Scalar(1.0 - 0.22 * warm + 0.06 * in.overcast, 1.0 - 0.05 * warm, 1.0 + 0.18 * warm - 0.04 * in.overcast);
  return l;
}

namespace {

// The people, each with its cover (foliage on grass and mixed ground, else rubble).
void AddFigures(const WorldConfig& config, RenderScene* s) {
  const bool vegetation = !config.terrain || config.terrain->kind == TerrainKind::kGrass ||
                          config.terrain->kind == TerrainKind::kMixed;
  for (std::size_t i = 0; i < config.victims.size(); ++i) {
    const Victim& v = config.victims[i];
    Figure f;
    f.victim = i;
    f.parts = FigureParts(v);
    f.cover = CoverParts(v, f.parts, vegetation, Mix(config.ground_texture_seed ^ HashOf(v.id)));
    f.centre_m = {v.x_m, v.y_m, 0};
    f.radius_m = 1.5 * v.height_m / 1.75 + 0.4;
    f.clothing_pass = kClothingPass[(HashOf(v.id) >> 28) % kClothingPass.size()];
    s->figures.push_back(std::move(f));
  }
}

// The distractors (flats), and the boxes and trees sorted by top height (painter's order).
void AddFlatsAndObstacles(const WorldConfig& config, RenderScene* s) {
  for (std::size_t i = 0; i < config.distractors.size(); ++i) {
    s->flats.push_back(DistractorDrawable(config.distractors[i], Mix(config.ground_texture_seed * 31 + i)));
  }
  for (const ObstacleBox& b : config.obstacles) {
    s->obstacles.push_back(b.kind == ObstacleKind::kTree ? TreeDrawable(b, Mix(config.ground_texture_seed ^ HashOf(b.id)), s->light)
                                                         : BoxDrawable(b));
  }
  std::stable_sort(s->obstacles.begin(), s->obstacles.end(), [](const Drawable& l, const Drawable& r) { return l.top_m < r.top_m; });
}

// What throws a shadow: obstacles and trees, distractors taller than 0.1 m, people upright.
std::vector<const std::vector<Part>*> ShadowCasters(const WorldConfig& config, const RenderScene& s) {
  std::vector<const std::vector<Part>*> casters;
  for (const Drawable& d : s.obstacles) casters.push_back(&d.parts);
  for (const Drawable& d : s.flats) {
    if (d.top_m > 0.1) casters.push_back(&d.parts);
  }
  for (const Figure& f : s.figures) {
    const VictimPose pose = config.victims[f.victim].pose;
    if (pose == VictimPose::kStanding || pose == VictimPose::kSitting) casters.push_back(&f.parts);
  }
  return casters;
}

}  // namespace

RenderScene BuildScene(const WorldConfig& config) {
  RenderScene s;
  constexpr double kMarginM = 60;  // texture beyond the geofence (what a camera at the edge sees)
  const int cols = static_cast<int>(std::ceil((config.size_x_m + 2 * kMarginM) / s.texel_m));
  const int rows = static_cast<int>(std::ceil((config.size_y_m + 2 * kMarginM) / s.texel_m));
  s.origin_x_m = -config.size_x_m / 2 - kMarginM;
  s.top_y_m = config.size_y_m / 2 + kMarginM;
  s.texture.create(rows, cols, CV_8UC3);
  s.vegetation = cv::Mat(rows, cols, CV_8U, cv::Scalar(0));
  s.wet = cv::Mat(rows, cols, CV_8U, cv::Scalar(0));
  s.shadow = cv::Mat(rows, cols, CV_8U, cv::Scalar(0));
  if (config.terrain) {
    TerrainTexture(config, *config.terrain, s.texel_m, s.origin_x_m, s.top_y_m, &s.texture, &s.vegetation,
                   &s.wet);
  } else {
    LegacyTexture(config, &s.texture, &s.vegetation);
  }
  s.light = LightOf(config);
  AddFigures(config, &s);
  AddFlatsAndObstacles(config, &s);
  BakeShadows(ShadowCasters(config, s), s.light, s.texel_m, s.origin_x_m, s.top_y_m, &s.texture, &s.shadow);
  return s;
}

}  // namespace swarmbox::physics::detail
