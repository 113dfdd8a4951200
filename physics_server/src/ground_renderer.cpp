#include "swarmbox/physics/ground_renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace swarmbox::physics {
namespace {

// 3x3 rotation (row-major) from a unit quaternion (body -> world).
std::array<double, 9> RotationOf(const Quat& q) {
  const double w = q.w, x = q.x, y = q.y, z = q.z;
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

Quat QuatOf(const std::array<double, 9>& m) {
  // Shepperd's method.
  const double tr = m[0] + m[4] + m[8];
  Quat q;
  if (tr > 0) {
    const double s = std::sqrt(tr + 1.0) * 2;
    q = {0.25 * s, (m[7] - m[5]) / s, (m[2] - m[6]) / s, (m[3] - m[1]) / s};
  } else if (m[0] > m[4] && m[0] > m[8]) {
    const double s = std::sqrt(1.0 + m[0] - m[4] - m[8]) * 2;
    q = {(m[7] - m[5]) / s, 0.25 * s, (m[1] + m[3]) / s, (m[2] + m[6]) / s};
  } else if (m[4] > m[8]) {
    const double s = std::sqrt(1.0 + m[4] - m[0] - m[8]) * 2;
    q = {(m[2] - m[6]) / s, (m[1] + m[3]) / s, 0.25 * s, (m[5] + m[7]) / s};
  } else {
    const double s = std::sqrt(1.0 + m[8] - m[0] - m[4]) * 2;
    q = {(m[3] - m[1]) / s, (m[2] + m[6]) / s, (m[5] + m[7]) / s, 0.25 * s};
  }
  return q;
}

// Body axes of the optical frame: x_c = -y_b, y_c = -x_b, z_c = -z_b (columns).
constexpr std::array<double, 9> kBodyFromOptical = {0, -1, 0,  //
                                                    -1, 0, 0,  //
                                                    0, 0, -1};

std::array<double, 9> Mul(const std::array<double, 9>& a, const std::array<double, 9>& b) {
  std::array<double, 9> c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) c[static_cast<std::size_t>(i * 3 + j)] += a[static_cast<std::size_t>(i * 3 + k)] * b[static_cast<std::size_t>(k * 3 + j)];
  return c;
}

// Projects world points through the optical camera; returns false if any lies behind it.
struct Projector {
  std::array<double, 9> r_wc;  // optical -> world (columns: optical axes in world)
  Vec3 c;                      // camera centre, world
  CameraIntrinsics k;

  bool Project(const Vec3& p, cv::Point2f* out) const {
    const Vec3 d = p - c;
    const double xc = r_wc[0] * d.x + r_wc[3] * d.y + r_wc[6] * d.z;
    const double yc = r_wc[1] * d.x + r_wc[4] * d.y + r_wc[7] * d.z;
    const double zc = r_wc[2] * d.x + r_wc[5] * d.y + r_wc[8] * d.z;
    if (zc < 0.05) return false;
    *out = cv::Point2f(static_cast<float>(k.fx_px * xc / zc + k.cx_px), static_cast<float>(k.fy_px * yc / zc + k.cy_px));
    return true;
  }
};

// Projects a convex 3D polygon to a fixed-point convex hull (kShift fractional bits); false when
// any vertex lies behind the camera.
constexpr int kShift = 4;  // sub-pixel accuracy for fillConvexPoly
bool ProjectHull(const Projector& cam, const std::vector<Vec3>& pts, std::vector<cv::Point>* hull) {
  std::vector<cv::Point> poly;
  poly.reserve(pts.size());
  for (const Vec3& p : pts) {
    cv::Point2f q;
    if (!cam.Project(p, &q)) return false;
    poly.emplace_back(static_cast<int>(std::lround(q.x * (1 << kShift))), static_cast<int>(std::lround(q.y * (1 << kShift))));
  }
  cv::convexHull(poly, *hull);
  return true;
}

// Fills the projected polygon in `img` and, when `labels` is set, writes `label` there too
// (a person's index + 1, or 0 for what hides people).
void FillProjected(cv::Mat& img, const Projector& cam, const std::vector<Vec3>& pts, const cv::Scalar& colour,
                   cv::Mat* labels = nullptr, int label = 0) {
  std::vector<cv::Point> hull;
  if (!ProjectHull(cam, pts, &hull)) return;
  cv::fillConvexPoly(img, hull, colour, cv::LINE_8, kShift);
  if (labels != nullptr) cv::fillConvexPoly(*labels, hull, cv::Scalar(label), cv::LINE_8, kShift);
}

// Bounding box (whole pixels) of the projected polygons; false if any point is behind the camera.
bool ProjectedBounds(const Projector& cam, const std::vector<std::vector<Vec3>>& shapes, cv::Rect* box) {
  float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
  for (const auto& pts : shapes) {
    for (const Vec3& p : pts) {
      cv::Point2f q;
      if (!cam.Project(p, &q)) return false;
      x0 = std::min(x0, q.x), y0 = std::min(y0, q.y), x1 = std::max(x1, q.x), y1 = std::max(y1, q.y);
    }
  }
  // fillConvexPoly covers pixel centres within the polygon (pixel (x, y) is centred on (x, y)).
  const int ix0 = static_cast<int>(std::floor(x0)), iy0 = static_cast<int>(std::floor(y0));
  *box = cv::Rect(ix0, iy0, static_cast<int>(std::ceil(x1)) - ix0 + 1, static_cast<int>(std::ceil(y1)) - iy0 + 1);
  return true;
}

// Pixels the polygons cover when drawn whole (also outside the image), with `scratch` as canvas.
double FullAreaPx(const Projector& cam, const std::vector<std::vector<Vec3>>& shapes, const cv::Rect& box,
                  cv::Mat* scratch) {
  constexpr int kMaxSide = 4096;  // a figure filling more than this is measured by its polygons
  if (box.width > kMaxSide || box.height > kMaxSide) {
    double area = 0;
    for (const auto& pts : shapes) {
      std::vector<cv::Point> hull;
      if (ProjectHull(cam, pts, &hull)) area += cv::contourArea(hull) / double(1 << (2 * kShift));
    }
    return area;
  }
  scratch->create(box.height, box.width, CV_8U);
  scratch->setTo(0);
  const cv::Point offset(-box.x * (1 << kShift), -box.y * (1 << kShift));
  for (const auto& pts : shapes) {
    std::vector<cv::Point> hull;
    if (!ProjectHull(cam, pts, &hull)) continue;
    for (cv::Point& p : hull) p += offset;
    cv::fillConvexPoly(*scratch, hull, cv::Scalar(1), cv::LINE_8, kShift);
  }
  return cv::countNonZero(*scratch);
}

std::vector<Vec3> Ellipse(double cx, double cy, double heading, double a, double b, double z) {
  std::vector<Vec3> pts;
  constexpr int kN = 20;
  const double ch = std::cos(heading), sh = std::sin(heading);
  for (int i = 0; i < kN; ++i) {
    const double t = 2 * std::numbers::pi * i / kN;
    const double u = a * std::cos(t), v = b * std::sin(t);
    pts.push_back({cx + u * ch - v * sh, cy + u * sh + v * ch, z});
  }
  return pts;
}

constexpr int kNoiseTilePx = 1024;
constexpr double kNoiseScale = 16.0;  // tile std; frames rescale to their noise_std

}  // namespace

CameraIntrinsics IntrinsicsFor(const CameraSpec& spec) {
  CameraIntrinsics k;
  k.fx_px = spec.width_px / 2.0 / std::tan(spec.hfov_rad / 2);
  k.fy_px = k.fx_px;
  k.cx_px = spec.width_px / 2.0;
  k.cy_px = spec.height_px / 2.0;
  return k;
}

Pose OpticalPose(const Pose& body, const CameraSpec& spec) {
  Pose p;
  p.position_m = body.position_m + Rotate(body.attitude, spec.offset_m);
  p.attitude = QuatOf(Mul(RotationOf(body.attitude), kBodyFromOptical));
  return p;
}

GroundRenderer::GroundRenderer(const WorldConfig& config) : config_(&config) {
  constexpr double kMarginM = 60;  // texture beyond the geofence (what a camera at the edge sees)
  labels_.create(1, 1, CV_16U);
  const int cols = static_cast<int>(std::ceil((config.size_x_m + 2 * kMarginM) / texel_m_));
  const int rows = static_cast<int>(std::ceil((config.size_y_m + 2 * kMarginM) / texel_m_));
  origin_x_m_ = -config.size_x_m / 2 - kMarginM;
  top_y_m_ = config.size_y_m / 2 + kMarginM;

  // Value noise: a few octaves of random grids, upsampled smoothly, summed.
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
  // Fine grain per texel.
  cv::Mat grain(rows, cols, CV_32F);
  rng.fill(grain, cv::RNG::NORMAL, 0.0, 0.06);
  acc += grain;

  texture_.create(rows, cols, CV_8UC3);
  for (int r = 0; r < rows; ++r) {
    const float* a = acc.ptr<float>(r);
    const float* s = soil.ptr<float>(r);
    auto* px = texture_.ptr<cv::Vec3b>(r);
    for (int c = 0; c < cols; ++c) {
      const float v = std::clamp(a[c], 0.0f, 1.2f);
      const float soil_mix = std::clamp((s[c] - 0.62f) * 4.0f, 0.0f, 1.0f);  // brown patches
      // grass: B 30..70, G 80..150, R 40..90; soil: B 50..80, G 70..100, R 90..120
      const float gb = 30 + 40 * v, gg = 80 + 70 * v, gr = 40 + 50 * v;
      const float sb = 50 + 30 * v, sg = 70 + 30 * v, sr = 90 + 30 * v;
      px[c] = cv::Vec3b(cv::saturate_cast<std::uint8_t>(gb + (sb - gb) * soil_mix),
                        cv::saturate_cast<std::uint8_t>(gg + (sg - gg) * soil_mix),
                        cv::saturate_cast<std::uint8_t>(gr + (sr - gr) * soil_mix));
    }
  }
}

GroundRenderer::~GroundRenderer() = default;

void GroundRenderer::Render(const Pose& body_pose, const CameraSpec& spec, std::uint64_t noise_seed,
                            CameraImage* out, std::vector<VisiblePerson>* people) {
  Render(body_pose, Vec3{}, spec, noise_seed, out, people);
}

void GroundRenderer::Render(const Pose& body_pose, const Vec3& /*body_rates_rad_s*/, const CameraSpec& spec,
                            std::uint64_t noise_seed, CameraImage* out, std::vector<VisiblePerson>* people) {
  if (people != nullptr) people->clear();
  const int w = spec.width_px, h = spec.height_px;
  out->width_px = w;
  out->height_px = h;
  out->intrinsics = IntrinsicsFor(spec);
  out->camera_pose = OpticalPose(body_pose, spec);
  out->bgr.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3);
  cv::Mat img(h, w, CV_8UC3, out->bgr.data());

  const CameraIntrinsics& k = out->intrinsics;
  const Projector cam{Mul(RotationOf(body_pose.attitude), kBodyFromOptical), out->camera_pose.position_m, k};
  const auto& R = cam.r_wc;
  const Vec3& C = cam.c;

  // Ground: homography texel -> pixel. pixel ~ K * R_cw * [e1 e2 -C] * T * texel.
  cv::Matx33d K(k.fx_px, 0, k.cx_px, 0, k.fy_px, k.cy_px, 0, 0, 1);
  cv::Matx33d Rcw(R[0], R[3], R[6], R[1], R[4], R[7], R[2], R[5], R[8]);
  cv::Matx33d M(1, 0, -C.x, 0, 1, -C.y, 0, 0, -C.z);
  cv::Matx33d T(texel_m_, 0, origin_x_m_ + texel_m_ / 2, 0, -texel_m_, top_y_m_ - texel_m_ / 2, 0, 0, 1);
  const cv::Matx33d H = K * Rcw * M * T;
  if (C.z > 0.01) {
    cv::warpPerspective(texture_, img, cv::Mat(H), img.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT101);
  } else {
    img.setTo(cv::Scalar(40, 60, 70));  // camera at/below the ground: dark
  }

  // Sky: pixels whose ray has world z >= 0. ray_w.z = a*u + b*v + c, a half-plane of the image.
  {
    const double a = R[6] / k.fx_px, b = R[7] / k.fy_px;
    const double c = R[8] - R[6] * k.cx_px / k.fx_px - R[7] * k.cy_px / k.fy_px;
    std::vector<cv::Point2d> rect = {{0, 0}, {double(w), 0}, {double(w), double(h)}, {0, double(h)}};
    std::vector<cv::Point> sky;
    auto f = [&](const cv::Point2d& p) { return a * p.x + b * p.y + c + 1e-3; };  // >= 0: sky
    for (std::size_t i = 0; i < rect.size(); ++i) {
      const cv::Point2d& p = rect[i];
      const cv::Point2d& q = rect[(i + 1) % rect.size()];
      const double fp = f(p), fq = f(q);
      if (fp >= 0) sky.emplace_back(cv::Point(static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y))));
      if ((fp >= 0) != (fq >= 0)) {
        const double t = fp / (fp - fq);
        const cv::Point2d x = p + (q - p) * t;
        sky.emplace_back(cv::Point(static_cast<int>(std::lround(x.x)), static_cast<int>(std::lround(x.y))));
      }
    }
    if (sky.size() >= 3) cv::fillConvexPoly(img, sky, cv::Scalar(235, 206, 135));
  }

  // Truth: each person's label (index + 1) under everything drawn over it; 0 elsewhere.
  cv::Mat* labels = nullptr;
  if (people != nullptr) {
    labels_.create(h, w, CV_16U);
    labels_.setTo(0);
    labels = &labels_;
  }
  const cv::Rect frame(0, 0, w, h);
  struct InView {
    std::size_t index;
    cv::Rect box;  // unclipped
  };
  std::vector<InView> in_view;

  // Victims (on the ground, under any obstacle drawn later).
  for (std::size_t i = 0; i < config_->victims.size(); ++i) {
    const Victim& v = config_->victims[i];
    const double ch = std::cos(v.heading_rad), sh = std::sin(v.heading_rad);
    const std::vector<std::vector<Vec3>> shapes = {
        Ellipse(v.x_m - 0.15 * ch, v.y_m - 0.15 * sh, v.heading_rad, 0.72, 0.24, 0.0),
        Ellipse(v.x_m + 0.7 * ch, v.y_m + 0.7 * sh, v.heading_rad, 0.13, 0.11, 0.0)};
    cv::Rect box;
    if (!ProjectedBounds(cam, shapes, &box) || (box & frame).empty()) continue;
    const int label = static_cast<int>(i + 1);
    FillProjected(img, cam, shapes[0], cv::Scalar(kVictimBodyBgr[0], kVictimBodyBgr[1], kVictimBodyBgr[2]), labels, label);
    FillProjected(img, cam, shapes[1], cv::Scalar(kVictimHeadBgr[0], kVictimHeadBgr[1], kVictimHeadBgr[2]), labels, label);
    if (people != nullptr) in_view.push_back({i, box});
  }

  // Obstacles, lowest top first.
  std::vector<const ObstacleBox*> boxes;
  boxes.reserve(config_->obstacles.size());
  for (const ObstacleBox& b : config_->obstacles) boxes.push_back(&b);
  std::stable_sort(boxes.begin(), boxes.end(), [](const ObstacleBox* l, const ObstacleBox* r) {
    return l->center_m.z + l->size_m.z / 2 < r->center_m.z + r->size_m.z / 2;
  });
  for (const ObstacleBox* b : boxes) {
    const double cy = std::cos(b->yaw_rad), sy = std::sin(b->yaw_rad);
    std::vector<Vec3> all, top;
    for (int i = 0; i < 8; ++i) {
      const double dx = ((i & 1) ? 0.5 : -0.5) * b->size_m.x;
      const double dy = ((i & 2) ? 0.5 : -0.5) * b->size_m.y;
      const double dz = ((i & 4) ? 0.5 : -0.5) * b->size_m.z;
      const Vec3 p{b->center_m.x + dx * cy - dy * sy, b->center_m.y + dx * sy + dy * cy, b->center_m.z + dz};
      all.push_back(p);
      if (i & 4) top.push_back(p);
    }
    if (C.z > b->center_m.z + b->size_m.z / 2) {
      FillProjected(img, cam, all, cv::Scalar(70, 75, 80), labels, 0);
      FillProjected(img, cam, top, cv::Scalar(150, 155, 160));
    } else {
      FillProjected(img, cam, all, cv::Scalar(90, 95, 100), labels, 0);
    }
  }

  // What is left of each person in view.
  if (people != nullptr) {
    for (const InView& p : in_view) {
      const Victim& v = config_->victims[p.index];
      const cv::Rect clipped = p.box & frame;
      cv::Mat same;
      cv::compare(labels_(clipped), cv::Scalar(static_cast<double>(p.index + 1)), same, cv::CMP_EQ);
      const int seen = cv::countNonZero(same);
      if (seen == 0) continue;
      const double ch = std::cos(v.heading_rad), sh = std::sin(v.heading_rad);
      const std::vector<std::vector<Vec3>> shapes = {
          Ellipse(v.x_m - 0.15 * ch, v.y_m - 0.15 * sh, v.heading_rad, 0.72, 0.24, 0.0),
          Ellipse(v.x_m + 0.7 * ch, v.y_m + 0.7 * sh, v.heading_rad, 0.13, 0.11, 0.0)};
      const double full = FullAreaPx(cam, shapes, p.box, &scratch_);
      people->push_back({v.id, clipped, std::min(1.0, seen / std::max(1.0, full))});
    }
  }

  if (spec.noise_std > 0) {
    if (noise_tile_.empty()) {
      cv::RNG tile_rng(0x6E015E);
      noise_tile_.create(kNoiseTilePx, kNoiseTilePx, CV_16SC3);
      tile_rng.fill(noise_tile_, cv::RNG::NORMAL, 0.0, kNoiseScale);
    }
    cv::RNG rng(noise_seed);
    const int x0 = rng.uniform(0, kNoiseTilePx - std::min(w, kNoiseTilePx) + 1);
    const int y0 = rng.uniform(0, kNoiseTilePx - std::min(h, kNoiseTilePx) + 1);
    // Images larger than the tile (rare) reuse it in pieces.
    cv::Mat scaled;
    for (int ty = 0, ch = 0; ty < h; ty += ch) {
      const int sy = ty == 0 ? y0 : 0;
      ch = std::min(kNoiseTilePx - sy, h - ty);
      for (int tx = 0, cw = 0; tx < w; tx += cw) {
        const int sx = tx == 0 ? x0 : 0;
        cw = std::min(kNoiseTilePx - sx, w - tx);
        noise_tile_(cv::Rect(sx, sy, cw, ch)).convertTo(scaled, CV_16SC3, spec.noise_std / kNoiseScale);
        cv::Mat target = img(cv::Rect(tx, ty, cw, ch));
        cv::add(target, scaled, target, cv::noArray(), CV_8UC3);
      }
    }
  }
}

}  // namespace swarmbox::physics
