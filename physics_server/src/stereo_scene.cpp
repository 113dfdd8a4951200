#include "swarmbox/physics/stereo_scene.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace swarmbox::physics {
namespace {

// Smooth seeded noise in [-1, 1]-ish (zero mean, unit-ish std): white noise at `scale_m`
// resolution, resized with cubic interpolation to the scene grid.
cv::Mat SmoothNoise(int rows, int cols, double cell_m, double scale_m, cv::RNG& rng) {
  const int r = std::max(2, static_cast<int>(std::ceil(rows * cell_m / scale_m)) + 1);
  const int c = std::max(2, static_cast<int>(std::ceil(cols * cell_m / scale_m)) + 1);
  cv::Mat coarse(r, c, CV_32F);
  rng.fill(coarse, cv::RNG::NORMAL, 0.0, 1.0);
  cv::Mat fine;
  cv::resize(coarse, fine, cv::Size(cols, rows), 0, 0, cv::INTER_CUBIC);
  return fine;
}

StereoScene Blank(double size_m, double cell_m, float albedo, float ambient) {
  StereoScene s;
  s.cell_m = cell_m;
  const int n = static_cast<int>(std::ceil(size_m / cell_m));
  s.origin_x_m = -size_m / 2 + cell_m / 2;
  s.origin_y_m = -size_m / 2 + cell_m / 2;
  s.height_m = cv::Mat::zeros(n, n, CV_32F);
  s.albedo = cv::Mat(n, n, CV_32F, cv::Scalar(albedo));
  s.ambient_w_m2 = cv::Mat(n, n, CV_32F, cv::Scalar(ambient));
  return s;
}

// Multiplies the albedo by (1 + ripple * noise) over a few scales (fine grain to patches).
void Ripple(StereoScene* s, double ripple, cv::RNG& rng) {
  const int rows = s->albedo.rows, cols = s->albedo.cols;
  cv::Mat sum = cv::Mat::zeros(rows, cols, CV_32F);
  for (double scale : {s->cell_m, 0.2, 1.0}) sum += SmoothNoise(rows, cols, s->cell_m, scale, rng) * (1.0 / 3.0);
  cv::Mat factor = 1.0 + sum * ripple;
  cv::multiply(s->albedo, factor, s->albedo);
}

constexpr double kCell_m = 0.05;  // the benchmark surfaces' grid
constexpr auto kSun_w_m2 = static_cast<float>(kSunInBandWm2);

// Rubble's texture: broken concrete, brick and dust, strong contrast over several scales.
void AddRubbleTexture(StereoScene* s, cv::RNG& rng) {
  cv::Mat tex = SmoothNoise(s->albedo.rows, s->albedo.cols, kCell_m, kCell_m, rng) * 0.08 +
                SmoothNoise(s->albedo.rows, s->albedo.cols, kCell_m, 0.3, rng) * 0.10 +
                SmoothNoise(s->albedo.rows, s->albedo.cols, kCell_m, 1.5, rng) * 0.05;
  s->albedo += tex;
}

// Raises the cells around (cx, cy) to a Gaussian mound of height `h` (keeping higher cells),
// cut off at 3 sigma.
void RaiseMound(StereoScene* s, double cx, double cy, double h, double sigma) {
  const int r = static_cast<int>(3 * sigma / kCell_m);
  const int col = static_cast<int>((cx - s->origin_x_m) / kCell_m), row = static_cast<int>((cy - s->origin_y_m) / kCell_m);
  for (int y = std::max(0, row - r); y < std::min(s->height_m.rows, row + r); ++y) {
    auto* hp = s->height_m.ptr<float>(y);
    for (int x = std::max(0, col - r); x < std::min(s->height_m.cols, col + r); ++x) {
      const double dx = (x - col) * kCell_m, dy = (y - row) * kCell_m;
      hp[x] = std::max(hp[x], static_cast<float>(h * std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma))));
    }
  }
}

// Heaps: smooth mounds up to ~1.2 m, one per 40 m^2.
void AddHeaps(StereoScene* s, double size_m, cv::RNG& rng) {
  const int heaps = static_cast<int>(size_m * size_m / 40.0);
  for (int i = 0; i < heaps; ++i) {
    const double cx = rng.uniform(-size_m / 2, size_m / 2), cy = rng.uniform(-size_m / 2, size_m / 2);
    const double h = rng.uniform(0.3, 1.2), sigma = rng.uniform(0.8, 2.5);
    RaiseMound(s, cx, cy, h, sigma);
  }
}

// Chunks: slabs and bricks lying on the heaps, one per 4 m^2.
void AddChunks(StereoScene* s, double size_m, cv::RNG& rng) {
  const int chunks = static_cast<int>(size_m * size_m / 4.0);
  for (int i = 0; i < chunks; ++i) {
    const Vec3 c{rng.uniform(-size_m / 2, size_m / 2), rng.uniform(-size_m / 2, size_m / 2), 0};
    const Vec3 sz{rng.uniform(0.15, 0.7), rng.uniform(0.15, 0.7), 0};
    const double top = s->HeightAt(c.x, c.y) + rng.uniform(0.05, 0.3);
    AddBox(s, c, sz, top, rng.uniform(0.15, 0.65));
  }
}

StereoScene MakeRubble(double size_m, cv::RNG& rng) {
  StereoScene s = Blank(size_m, kCell_m, 0.35f, kSun_w_m2);
  AddRubbleTexture(&s, rng);
  AddHeaps(&s, size_m, rng);
  s.height_m += SmoothNoise(s.height_m.rows, s.height_m.cols, kCell_m, 0.25, rng) * 0.03;
  AddChunks(&s, size_m, rng);
  cv::max(s.albedo, 0.02, s.albedo);
  cv::min(s.albedo, 0.95, s.albedo);
  s.UpdateHeightRange();
  return s;
}

StereoScene MakeConcreteShade(double size_m, cv::RNG& rng) {
  StereoScene s = Blank(size_m, kCell_m, 0.45f, kSun_w_m2 * static_cast<float>(kShadeFraction));
  Ripple(&s, 0.01, rng);
  s.UpdateHeightRange();
  return s;
}

StereoScene MakeSandSun(double size_m, cv::RNG& rng) {
  StereoScene s = Blank(size_m, kCell_m, 0.55f, kSun_w_m2);
  Ripple(&s, 0.01, rng);
  cv::Mat dunes = SmoothNoise(s.height_m.rows, s.height_m.cols, kCell_m, 6.0, rng) * 0.1 + 0.15;
  cv::max(dunes, 0.0, s.height_m);
  s.UpdateHeightRange();
  return s;
}

}  // namespace

float StereoScene::HeightAt(double x_m, double y_m) const {
  const double fx = std::clamp((x_m - origin_x_m) / cell_m, 0.0, height_m.cols - 1.001);
  const double fy = std::clamp((y_m - origin_y_m) / cell_m, 0.0, height_m.rows - 1.001);
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  const float ax = static_cast<float>(fx - ix), ay = static_cast<float>(fy - iy);
  const float* r0 = height_m.ptr<float>(iy);
  const float* r1 = height_m.ptr<float>(iy + 1);
  return (r0[ix] * (1 - ax) + r0[ix + 1] * ax) * (1 - ay) + (r1[ix] * (1 - ax) + r1[ix + 1] * ax) * ay;
}

void StereoScene::UpdateHeightRange() {
  double lo = 0, hi = 0;
  cv::minMaxLoc(height_m, &lo, &hi);
  min_height_m = static_cast<float>(lo);
  max_height_m = static_cast<float>(hi);
}

double BoundingRadiusM(const SceneBox& box) {
  return std::sqrt(Dot(box.half_size_m, box.half_size_m));
}

bool MayBeInView(const SceneBox& box, const Vec3& camera_m, double half_size_m) {
  const double reach_m = half_size_m + BoundingRadiusM(box);
  return std::abs(box.centre_m.x - camera_m.x) <= reach_m && std::abs(box.centre_m.y - camera_m.y) <= reach_m &&
         box.centre_m.z - BoundingRadiusM(box) < camera_m.z;
}

const char* StereoSurfaceName(StereoSurface surface) {
  switch (surface) {
    case StereoSurface::kRubble: return "rubble";
    case StereoSurface::kConcreteShade: return "concrete_shade";
    case StereoSurface::kSandSun: return "sand_sun";
  }
  return "?";
}

StereoScene MakeSurfaceScene(StereoSurface surface, double size_m, std::uint64_t seed) {
  cv::RNG rng(seed);
  switch (surface) {
    case StereoSurface::kRubble: return MakeRubble(size_m, rng);
    case StereoSurface::kConcreteShade: return MakeConcreteShade(size_m, rng);
    case StereoSurface::kSandSun: return MakeSandSun(size_m, rng);
  }
  return {};
}

void AddBox(StereoScene* scene, const Vec3& centre_m, const Vec3& size_m, double top_m, double albedo) {
  const double c = scene->cell_m;
  const int x0 = std::max(0, static_cast<int>(std::ceil((centre_m.x - size_m.x / 2 - scene->origin_x_m) / c)));
  const int x1 = std::min(scene->height_m.cols - 1, static_cast<int>(std::floor((centre_m.x + size_m.x / 2 - scene->origin_x_m) / c)));
  const int y0 = std::max(0, static_cast<int>(std::ceil((centre_m.y - size_m.y / 2 - scene->origin_y_m) / c)));
  const int y1 = std::min(scene->height_m.rows - 1, static_cast<int>(std::floor((centre_m.y + size_m.y / 2 - scene->origin_y_m) / c)));
  for (int y = y0; y <= y1; ++y) {
    auto* h = scene->height_m.ptr<float>(y);
    auto* a = scene->albedo.ptr<float>(y);
    for (int x = x0; x <= x1; ++x) {
      h[x] = std::max(h[x], static_cast<float>(top_m));
      a[x] = static_cast<float>(albedo);
    }
  }
  if (x0 <= x1 && y0 <= y1) scene->max_height_m = std::max(scene->max_height_m, static_cast<float>(top_m));
}

}  // namespace swarmbox::physics
