#include "swarmbox/physics/ground_renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "detail/render_scene.hpp"
#include "detail/scene_draw.hpp"

namespace swarmbox::physics {
namespace detail {
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
bool ProjectedBounds(const Projector& cam, const std::vector<detail::Part>& shapes, cv::Rect* box) {
  float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
  for (const auto& part : shapes) {
    for (const Vec3& p : part.pts) {
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
double FullAreaPx(const Projector& cam, const std::vector<detail::Part>& shapes, const cv::Rect& box,
                  cv::Mat* scratch) {
  constexpr int kMaxSide = 4096;  // a figure filling more than this is measured by its polygons
  if (box.width > kMaxSide || box.height > kMaxSide) {
    double area = 0;
    for (const auto& part : shapes) {
      std::vector<cv::Point> hull;
      if (ProjectHull(cam, part.pts, &hull)) area += cv::contourArea(hull) / double(1 << (2 * kShift));
    }
    return area;
  }
  scratch->create(box.height, box.width, CV_8U);
  scratch->setTo(0);
  const cv::Point offset(-box.x * (1 << kShift), -box.y * (1 << kShift));
  for (const auto& part : shapes) {
    std::vector<cv::Point> hull;
    if (!ProjectHull(cam, part.pts, &hull)) continue;
    for (cv::Point& p : hull) p += offset;
    cv::fillConvexPoly(*scratch, hull, cv::Scalar(1), cv::LINE_8, kShift);
  }
  return cv::countNonZero(*scratch);
}

// Whether a ground disc (centre, radius) can show in the image: its centre projects within the
// image grown by the disc's size in pixels at that range (a cheap cull before projecting parts).
bool MayShow(const Projector& cam, const Vec3& centre, double radius_m, int w, int h) {
  const Vec3 d = centre - cam.c;
  const double zc = cam.r_wc[2] * d.x + cam.r_wc[5] * d.y + cam.r_wc[8] * d.z;
  if (zc < 0.5) return true;  // close or behind: let the parts decide
  cv::Point2f q;
  if (!cam.Project(centre, &q)) return true;
  const double margin = cam.k.fx_px * (radius_m + 2.0) / zc;
  return q.x > -margin && q.y > -margin && q.x < w + margin && q.y < h + margin;
}

}  // namespace

// The ground plane z = 0 through one homography texel -> pixel:
// pixel ~ K * R_cw * [e1 e2 -C] * T * texel. A camera at or below the ground sees dark.
void DrawGround(const detail::RenderScene& scene, const Projector& cam, cv::Mat& img) {
  const auto& R = cam.r_wc;
  const Vec3& C = cam.c;
  const CameraIntrinsics& k = cam.k;
  cv::Matx33d K(k.fx_px, 0, k.cx_px, 0, k.fy_px, k.cy_px, 0, 0, 1);
  cv::Matx33d Rcw(R[0], R[3], R[6], R[1], R[4], R[7], R[2], R[5], R[8]);
  cv::Matx33d M(1, 0, -C.x, 0, 1, -C.y, 0, 0, -C.z);
  const double t = scene.texel_m;
  cv::Matx33d T(t, 0, scene.origin_x_m + t / 2, 0, -t, scene.top_y_m - t / 2, 0, 0, 1);
  const cv::Matx33d H = K * Rcw * M * T;
  if (C.z > 0.01) {
    cv::warpPerspective(scene.texture, img, cv::Mat(H), img.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT101);
  } else {
    img.setTo(scene.underground);
  }
}

// Sky: pixels whose ray has world z >= 0. ray_w.z = a*u + b*v + c, a half-plane of the image.
void DrawSky(const Projector& cam, const cv::Scalar& sky_colour, cv::Mat& img) {
  const auto& R = cam.r_wc;
  const CameraIntrinsics& k = cam.k;
  const int w = img.cols, h = img.rows;
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
      const double s = fp / (fp - fq);
      const cv::Point2d x = p + (q - p) * s;
      sky.emplace_back(cv::Point(static_cast<int>(std::lround(x.x)), static_cast<int>(std::lround(x.y))));
    }
  }
  if (sky.size() >= 3) cv::fillConvexPoly(img, sky, sky_colour);
}

// Distractors, then people (with their cover), then obstacles and trees, lowest top first; each
// person's label (index + 1) into `labels` (when set) under everything drawn over it. Appends the
// people in view to `in_view` when `want_people`.
void DrawScene(const detail::RenderScene& scene, const Projector& cam, cv::Mat& img, cv::Mat* labels, bool want_people,
               std::vector<InView>* in_view) {
  const int w = img.cols, h = img.rows;
  const cv::Rect frame(0, 0, w, h);
  for (const detail::Drawable& d : scene.flats) {
    if (!MayShow(cam, d.centre_m, d.radius_m, w, h)) continue;
    for (const detail::Part& p : d.parts) FillProjected(img, cam, p.pts, p.colour);
  }
  for (const detail::Figure& f : scene.figures) {
    if (!MayShow(cam, f.centre_m, f.radius_m, w, h)) continue;
    cv::Rect box;
    if (!ProjectedBounds(cam, f.parts, &box) || (box & frame).empty()) continue;
    const int label = static_cast<int>(f.victim + 1);
    for (const detail::Part& p : f.parts) FillProjected(img, cam, p.pts, p.colour, labels, label);
    for (const detail::Part& p : f.cover) FillProjected(img, cam, p.pts, p.colour, labels, 0);
    if (want_people) in_view->push_back({&f, box});
  }
  for (const detail::Drawable& d : scene.obstacles) {
    if (!MayShow(cam, d.centre_m, d.radius_m, w, h)) continue;
    if (d.is_box) {
      if (cam.c.z > d.top_m) {
        FillProjected(img, cam, d.parts[0].pts, d.parts[0].colour, labels, 0);
        FillProjected(img, cam, d.parts[1].pts, d.parts[1].colour);
      } else {
        FillProjected(img, cam, d.parts[0].pts, scene.box_below, labels, 0);
      }
      continue;
    }
    for (const detail::Part& p : d.parts) FillProjected(img, cam, p.pts, p.colour, labels, 0);
  }
}

// What is left of each person in view: `labels` holds the drawn truth (DrawScene), `scratch` is a
// canvas for a figure's full area.
void ListVisible(const WorldConfig& config, const cv::Mat& labels, const Projector& cam, const std::vector<InView>& in_view,
                 cv::Mat* scratch, std::vector<VisiblePerson>* people) {
  const cv::Rect frame(0, 0, labels.cols, labels.rows);
  for (const InView& p : in_view) {
    const cv::Rect clipped = p.box & frame;
    cv::Mat same;
    cv::compare(labels(clipped), cv::Scalar(static_cast<double>(p.figure->victim + 1)), same, cv::CMP_EQ);
    const int seen = cv::countNonZero(same);
    if (seen == 0) continue;
    const double full = FullAreaPx(cam, p.figure->parts, p.box, scratch);
    people->push_back({config.victims[p.figure->victim].id, clipped, std::min(1.0, seen / std::max(1.0, full))});
  }
}

Projector MakeProjector(const Pose& body_pose, const Pose& optical_pose, const CameraIntrinsics& k) {
  return Projector{Mul(RotationOf(body_pose.attitude), kBodyFromOptical), optical_pose.position_m, k};
}

Pose OpticalPoseAt(const Pose& body, const Vec3& offset_m) {
  Pose p;
  p.position_m = body.position_m + Rotate(body.attitude, offset_m);
  p.attitude = QuatOf(Mul(RotationOf(body.attitude), kBodyFromOptical));
  return p;
}

}  // namespace detail

namespace {

using detail::DrawGround;
using detail::DrawScene;
using detail::DrawSky;
using detail::InView;
using detail::ListVisible;
using detail::Projector;

constexpr int kNoiseTilePx = 1024;
constexpr double kNoiseScale = 16.0;  // tile std; frames rescale to their noise_std

// Exposure: auto-exposure lengthens the exposure as the light falls (up to 8x), then raises the
// analog gain (up to 4x); a frame's exposure misses its target by a seeded few per cent.
struct Exposure {
  double exposure_s;
  double gain = 1.0;    // applied to the pixels
  double analog = 1.0;  // scales the noise
};
Exposure ExposureOf(const detail::Light& light, const CameraSpec& spec, cv::RNG& rng) {
  Exposure e{spec.exposure_ms * 1e-3};
  if (light.enabled) {
    const double stretch = std::min(8.0, 1.0 / light.level);
    e.exposure_s *= stretch;
    e.analog = std::min(4.0, 1.0 / (light.level * stretch));
    e.gain = light.level * stretch * e.analog * (1.0 + 0.06 * std::clamp(rng.gaussian(1.0), -2.5, 2.5));
  }
  return e;
}

// Motion blur: the image moves by f * rate * exposure during the exposure (roll rate along u,
// pitch rate along v; the yaw rate's rotation about the optical axis is left out). Averages up
// to 16 shifted copies; `pad` and `acc` are scratch.
void MotionBlur(const CameraIntrinsics& k, const Vec3& body_rates_rad_s, double exposure_s, cv::Mat& img, cv::Mat* pad_img,
                cv::Mat* acc) {
  if (exposure_s <= 0) return;
  const int w = img.cols, h = img.rows;
  // Optical x = -body y, optical y = -body x: a body roll rate p (about +x) turns the view about
  // optical -y, moving the image along u; a pitch rate q along v.
  const double du = k.fx_px * body_rates_rad_s.x * exposure_s;
  const double dv = k.fy_px * body_rates_rad_s.y * exposure_s;
  const double len = std::hypot(du, dv);
  if (len < 1.0) return;
  const int n = std::min(16, static_cast<int>(std::ceil(len)) + 1);
  const int pad = static_cast<int>(std::ceil(len / 2)) + 1;
  cv::copyMakeBorder(img, *pad_img, pad, pad, pad, pad, cv::BORDER_REPLICATE);
  acc->create(h, w, CV_16UC3);
  acc->setTo(cv::Scalar::all(0));
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1) - 0.5;
    const int sx = static_cast<int>(std::lround(du * s)), sy = static_cast<int>(std::lround(dv * s));
    cv::add(*acc, (*pad_img)(cv::Rect(pad + sx, pad + sy, w, h)), *acc, cv::noArray(), CV_16UC3);
  }
  acc->convertTo(img, CV_8UC3, 1.0 / n);
}

// The light colour x vignetting map (8-bit, 100 = unit gain), rebuilt when the size or the
// vignetting changes.
void UpdateGainMap(const detail::Light& light, double vignetting, int w, int h, cv::Mat* map) {
  map->create(h, w, CV_8UC3);
  const double r2max = (w * w + h * h) / 4.0;
  for (int y = 0; y < h; ++y) {
    auto* g = map->ptr<cv::Vec3b>(y);
    for (int x = 0; x < w; ++x) {
      const double dx = x + 0.5 - w / 2.0, dy = y + 0.5 - h / 2.0;
      const double v = 1.0 - vignetting * (dx * dx + dy * dy) / r2max;
      for (int c = 0; c < 3; ++c) {
        g[x][c] = cv::saturate_cast<std::uint8_t>(100.0 * v * (light.enabled ? light.colour[c] : 1.0));
      }
    }
  }
}

// Light colour, exposure gain and vignetting in one multiply; `map` (and the vignetting it was
// built for) is kept between frames.
void ApplyGain(const detail::Light& light, double vignetting, double gain, cv::Mat& img, cv::Mat* map,
               double* map_vignetting) {
  if (!light.enabled && vignetting <= 0) return;
  if (map->size() != img.size() || *map_vignetting != vignetting) {
    UpdateGainMap(light, vignetting, img.cols, img.rows, map);
    *map_vignetting = vignetting;
  }
  cv::multiply(img, *map, img, gain / 100.0);
}

// Gaussian pixel noise: a seeded window of the pre-drawn tile, scaled to the frame's noise std
// (images larger than the tile, rare, reuse it in pieces).
void AddNoise(const cv::Mat& tile, double noise_std, cv::RNG& rng, cv::Mat& img) {
  const int w = img.cols, h = img.rows;
  const int x0 = rng.uniform(0, kNoiseTilePx - std::min(w, kNoiseTilePx) + 1);
  const int y0 = rng.uniform(0, kNoiseTilePx - std::min(h, kNoiseTilePx) + 1);
  cv::Mat scaled;
  for (int ty = 0, ch = 0; ty < h; ty += ch) {
    const int sy = ty == 0 ? y0 : 0;
    ch = std::min(kNoiseTilePx - sy, h - ty);
    for (int tx = 0, cw = 0; tx < w; tx += cw) {
      const int sx = tx == 0 ? x0 : 0;
      cw = std::min(kNoiseTilePx - sx, w - tx);
      tile(cv::Rect(sx, sy, cw, ch)).convertTo(scaled, CV_16SC3, noise_std / kNoiseScale);
      cv::Mat target = img(cv::Rect(tx, ty, cw, ch));
      cv::add(target, scaled, target, cv::noArray(), CV_8UC3);
    }
  }
}

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
  return detail::OpticalPoseAt(body, spec.offset_m);
}

GroundRenderer::GroundRenderer(const WorldConfig& config)
    : config_(&config), scene_(std::make_unique<detail::RenderScene>(detail::BuildScene(config))) {
  texel_m_ = scene_->texel_m;
  // The thermal scene's maps (ThermalSceneOf): not needed to draw colours.
  scene_->vegetation.release();
  scene_->wet.release();
  scene_->shadow.release();
}

GroundRenderer::~GroundRenderer() = default;

void GroundRenderer::Render(const Pose& body_pose, const CameraSpec& spec, std::uint64_t noise_seed,
                            CameraImage* out, std::vector<VisiblePerson>* people) {
  Render(body_pose, Vec3{}, spec, noise_seed, out, people);
}

void GroundRenderer::Render(const Pose& body_pose, const Vec3& body_rates_rad_s, const CameraSpec& spec,
                            std::uint64_t noise_seed, CameraImage* out, std::vector<VisiblePerson>* people) {
  if (people != nullptr) people->clear();
  const detail::RenderScene& scene = *scene_;
  const int w = spec.width_px, h = spec.height_px;
  out->width_px = w;
  out->height_px = h;
  out->intrinsics = IntrinsicsFor(spec);
  out->camera_pose = OpticalPose(body_pose, spec);
  out->bgr.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3);
  cv::Mat img(h, w, CV_8UC3, out->bgr.data());
  const Projector cam = detail::MakeProjector(body_pose, out->camera_pose, out->intrinsics);

  DrawGround(scene, cam, img);
  DrawSky(cam, scene.sky, img);
  cv::Mat* labels = nullptr;  // truth: each person's label (index + 1), 0 elsewhere
  if (people != nullptr) {
    labels_.create(h, w, CV_16U);
    labels_.setTo(0);
    labels = &labels_;
  }
  std::vector<InView> in_view;
  DrawScene(scene, cam, img, labels, people != nullptr, &in_view);
  if (people != nullptr) ListVisible(*config_, labels_, cam, in_view, &scratch_, people);

  cv::RNG rng(noise_seed);
  const Exposure e = ExposureOf(scene.light, spec, rng);
  MotionBlur(out->intrinsics, body_rates_rad_s, e.exposure_s, img, &blur_pad_, &blur_acc_);
  ApplyGain(scene.light, spec.vignetting, e.gain, img, &gain_map_, &gain_map_vignetting_);
  if (spec.noise_std > 0) {
    if (noise_tile_.empty()) {
      cv::RNG tile_rng(0x6E015E);
      noise_tile_.create(kNoiseTilePx, kNoiseTilePx, CV_16SC3);
      tile_rng.fill(noise_tile_, cv::RNG::NORMAL, 0.0, kNoiseScale);
    }
    AddNoise(noise_tile_, e.analog * spec.noise_std, rng, img);
  }
}

}  // namespace swarmbox::physics
