#include "swarmbox/physics/stereo_renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "swarmbox/physics/detail/mix64.hpp"

namespace swarmbox::physics {
namespace {

// Optical frame -> world rotation (row-major, columns = optical axes in world): optical
// x = body -y, y = body -x, z = body -z, as the RGB camera (ground_renderer.cpp).
std::array<double, 9> OpticalToWorld(const Quat& body) {
  const Vec3 ex = Rotate(body, Vec3{0, -1, 0});
  const Vec3 ey = Rotate(body, Vec3{-1, 0, 0});
  const Vec3 ez = Rotate(body, Vec3{0, 0, -1});
  return {ex.x, ey.x, ez.x, ex.y, ey.y, ez.y, ex.z, ey.z, ez.z};
}

Quat QuatOf(const std::array<double, 9>& m) {
  const double tr = m[0] + m[4] + m[8];
  if (tr > 0) {
    const double s = std::sqrt(tr + 1.0) * 2;
    return {0.25 * s, (m[7] - m[5]) / s, (m[2] - m[6]) / s, (m[3] - m[1]) / s};
  }
  if (m[0] > m[4] && m[0] > m[8]) {
    const double s = std::sqrt(1.0 + m[0] - m[4] - m[8]) * 2;
    return {(m[7] - m[5]) / s, 0.25 * s, (m[1] + m[3]) / s, (m[2] + m[6]) / s};
  }
  if (m[4] > m[8]) {
    const double s = std::sqrt(1.0 + m[4] - m[0] - m[8]) * 2;
    return {(m[2] - m[6]) / s, (m[1] + m[3]) / s, 0.25 * s, (m[5] + m[7]) / s};
  }
  const double s = std::sqrt(1.0 + m[8] - m[0] - m[4]) * 2;
  return {(m[3] - m[1]) / s, (m[2] + m[6]) / s, (m[5] + m[7]) / s, 0.25 * s};
}

constexpr double kPatternTanPerPx = 0.001;  // pattern sampling: ~5 samples across a dot
constexpr double kMaxGain = 400.0;          // auto-exposure limit [levels per W/m^2]
constexpr double kTargetLevel = 100.0;      // auto-exposure target (mean level of the left view)
constexpr float kSkyRadiance = 0.0f;        // rays that miss the ground (never, looking down)
constexpr double kMinDownward = 1e-6;       // a ray's world z below -this meets the ground
constexpr double kNearClip_m = 0.05;        // the march starts no nearer than this
constexpr double kEndMargin_m = 1e-3;       // the march ends this far below the lowest cell
constexpr double kProjectorNear_m = 0.05;   // no dots nearer the projector than this (optical z)

constexpr int kTileCells = 8;               // TileMax: tiles of 8 x 8 cells (0.4 m at 5 cm)
constexpr int kBlockTiles = 8;              // and blocks of 8 x 8 tiles (3.2 m)
constexpr int kBlockCells = kTileCells * kBlockTiles;
constexpr double kTileMargin_m = 1e-3;      // a sample this far above its tile's max is above the surface

int TileRows(const StereoScene& s) { return (s.height_m.rows + kTileCells - 1) / kTileCells; }

// The highest cell of each kTileCells square tile of a scene, over the tile's cells and the next
// row and column (the cells HeightAt's bilinear interpolation reads from inside the tile), so
// that HeightAt(x, y) <= the maximum of the tile of (x, y)'s cell anywhere, the grid's clamping
// included (the clamped cell's tile, as MarchToSurface finds it). Then, in the rows below them
// (one matrix, as the renderer keeps one), the highest of each block of kBlockTiles x kBlockTiles
// tiles: block (row, col) at (TileRows(s) + row, col).
void BuildTileMax(const StereoScene& s, cv::Mat* max_m) {
  const int rows = s.height_m.rows, cols = s.height_m.cols;
  const int tile_rows = TileRows(s), tile_cols = (cols + kTileCells - 1) / kTileCells;
  const int block_rows = (tile_rows + kBlockTiles - 1) / kBlockTiles;
  max_m->create(tile_rows + block_rows, tile_cols, CV_32F);
  for (int tr = 0; tr < tile_rows; ++tr) {
    for (int tc = 0; tc < tile_cols; ++tc) {
      const cv::Rect cells(tc * kTileCells, tr * kTileCells, std::min(kTileCells + 1, cols - tc * kTileCells),
                           std::min(kTileCells + 1, rows - tr * kTileCells));
      double hi = 0;
      cv::minMaxLoc(s.height_m(cells), nullptr, &hi);
      max_m->at<float>(tr, tc) = static_cast<float>(hi);
    }
  }
  for (int br = 0; br < block_rows; ++br) {
    for (int bc = 0; bc * kBlockTiles < tile_cols; ++bc) {
      const cv::Rect tiles(bc * kBlockTiles, br * kBlockTiles, std::min(kBlockTiles, tile_cols - bc * kBlockTiles),
                           std::min(kBlockTiles, tile_rows - br * kBlockTiles));
      double hi = 0;
      cv::minMaxLoc((*max_m)(tiles), nullptr, &hi);
      max_m->at<float>(tile_rows + br, bc) = static_cast<float>(hi);
    }
  }
}

// Along one grid axis, a ray's cell coordinate before clamping is f(t) = f0 + t * df (inv_df =
// 1 / df): the depth t at which its clamped coordinate leaves square `square` of `cells` cells
// (cells [square, square + 1) * cells); never when it moves towards a border inside that square
// (the clamp to [0, f_max] holds it there).
double SquareExitT(double f0, double df, double inv_df, int square, int cells, double f_max) {
  constexpr double kNever = std::numeric_limits<double>::infinity();
  if (df > 0) {
    const double edge = static_cast<double>((square + 1) * cells);
    return edge > f_max ? kNever : (edge - f0) * inv_df;
  }
  if (df < 0) return square == 0 ? kNever : (static_cast<double>(square * cells) - f0) * inv_df;
  return kNever;
}

// The ray centre + t * d in the height field's cell coordinates (HeightAt's, before clamping), with
// the reciprocals the jumps use.
struct CellRay {
  double fx0, dfx, inv_dfx, fy0, dfy, inv_dfy, fx_max, fy_max, z0, inv_down;
  CellRay(const StereoScene& s, const Vec3& centre, const Vec3& d)
      : fx0((centre.x - s.origin_x_m) / s.cell_m), dfx(d.x / s.cell_m), inv_dfx(1 / dfx),
        fy0((centre.y - s.origin_y_m) / s.cell_m), dfy(d.y / s.cell_m), inv_dfy(1 / dfy),
        fx_max(s.height_m.cols - 1.001), fy_max(s.height_m.rows - 1.001), z0(centre.z), inv_down(1 / -d.z) {}
};

// For the sample at depth tt and height z: when it is above its block's highest cell (else its
// tile's; + kTileMargin_m), the depth where the ray leaves that square sideways or comes down to that
// height (*t_leave), before which every sample is above the surface, and true; otherwise false (the
// sample needs the height field). The cell is clamped as HeightAt clamps it.
bool EmptyUntil(const cv::Mat& tile_max, int tile_rows, const CellRay& r, double tt, double z, double* t_leave) {
  const int col = static_cast<int>(std::clamp(r.fx0 + tt * r.dfx, 0.0, r.fx_max));
  const int row = static_cast<int>(std::clamp(r.fy0 + tt * r.dfy, 0.0, r.fy_max));
  int cells = kBlockCells;
  double top_m = tile_max.at<float>(tile_rows + row / kBlockCells, col / kBlockCells) + kTileMargin_m;
  if (!(z > top_m)) {
    cells = kTileCells;
    top_m = tile_max.at<float>(row / kTileCells, col / kTileCells) + kTileMargin_m;
  }
  if (!(z > top_m)) return false;
  *t_leave = std::min({(r.z0 - top_m) * r.inv_down, SquareExitT(r.fx0, r.dfx, r.inv_dfx, col / cells, cells, r.fx_max),
                       SquareExitT(r.fy0, r.dfy, r.inv_dfy, row / cells, cells, r.fy_max)});
  return true;
}

// Depth t (along the optical axis) where the ray centre + t * d (d.z < 0) first meets the height
// field: sampled at t0 + k * dt (k = 0, 1, ...; dt about one cell) from the highest cell's level
// down to the lowest's, then a secant between the last point above and the first below the
// surface. A ray that never dips below it ends at the lowest level. The samples are a lattice (k
// an integer, not t += dt accumulated) so that the jumps below land on the plain march's floating
// values. Empty-space skip: a sample well above its block's (3.2 m) or else its tile's (0.4 m)
// highest cell is above the surface, and so is every later sample until the ray leaves that
// square sideways or comes down to its highest cell (plus kTileMargin_m): the march jumps to the
// first lattice sample at or past that depth without reading the height field (over 26 m
// woodland, a ray beside the trees reaches the ground in a jump per block crossed, then a few per
// tile, instead of a step per cell). The sample before the crossing is then
// evaluated as the plain march would, so the result is the plain march's to the bit
// (stereo_test.cpp). The margin (1 mm) covers the rounding of the jump's depths (~1e-12 m): a
// sample the rounding puts a hair past the tile's edge reads the next tile's cells with weight
// ~1e-13.
double MarchToSurface(const StereoScene& s, const cv::Mat& tile_max, const Vec3& centre, const Vec3& d) {
  const double t_end = (centre.z - s.min_height_m) / -d.z + kEndMargin_m;
  const double dt = s.cell_m / std::max(std::hypot(d.x, d.y), -d.z);
  const double t0 = std::max(kNearClip_m, (centre.z - s.max_height_m) / -d.z);
  const CellRay ray(s, centre, d);
  const double inv_dt = 1 / dt;
  const int tile_rows = TileRows(s);
  double prev_t = t0, prev_f = 1.0;
  bool prev_skipped = false;
  for (double k = 0;; ++k) {  // k: a whole number in a double (exact far beyond any march's length)
    const double t = t0 + k * dt;
    if (!(t <= t_end + dt)) break;
    const double tt = std::min(t, t_end);
    const double z = centre.z + tt * d.z;
    double t_leave = 0;
    if (EmptyUntil(tile_max, tile_rows, ray, tt, z, &t_leave)) {
      prev_t = tt;
      prev_skipped = true;
      // Every sample before t_leave is above the surface (t_leave < t_end, as the square's top is
      // above the lowest cell): the next that may not be is k_next.
      const double k_next = std::ceil((t_leave - t0) * inv_dt);
      if (k_next - 1 > k) {
        k = k_next - 1;  // the loop's ++k takes it to k_next
        prev_t = t0 + k * dt;
      }
      continue;
    }
    const double x = centre.x + tt * d.x, y = centre.y + tt * d.y;
    if (prev_skipped) prev_f = centre.z + prev_t * d.z - s.HeightAt(centre.x + prev_t * d.x, centre.y + prev_t * d.y);
    prev_skipped = false;
    const double fz = z - s.HeightAt(x, y);
    if (fz <= 0) return fz == prev_f ? tt : prev_t + (tt - prev_t) * prev_f / (prev_f - fz);
    prev_t = tt;
    prev_f = fz;
  }
  return t_end;
}

// A box face's texture value at face point (u, v) [m], constant over cells of cell_m: uniform in
// [-1, 1), a function of the box's seed, the face and the cell alone.
double FaceNoise(std::uint64_t seed, int face, double u_m, double v_m, double cell_m) {
  const auto iu = static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(u_m / cell_m)));
  const auto iv = static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(v_m / cell_m)));
  const std::uint64_t h =
      detail::Mix64(seed ^ detail::Mix64(static_cast<std::uint64_t>(face) ^ detail::Mix64(iu ^ detail::Mix64(iv))));
  return 2 * (static_cast<double>(h >> 11) * 0x1.0p-53) - 1;
}

constexpr int kCoarseTextureCells = 4;      // the texture's coarse scale, in fine cells (0.2 m)
constexpr double kFineTextureShare = 0.6;   // the fine scale's share of the texture
constexpr float kMinBoxAlbedo = 0.02f, kMaxBoxAlbedo = 0.95f;

// The box's textured albedo at box-frame point p on face `axis` (0..2, the face's normal axis):
// the face's two other coordinates index the texture.
float BoxAlbedo(const SceneBox& b, int axis, const Vec3& p) {
  const double c[3] = {p.x, p.y, p.z};
  const double u = c[(axis + 1) % 3], v = c[(axis + 2) % 3];
  const int face = 2 * axis + (c[axis] > 0 ? 1 : 0);
  const double fine = FaceNoise(b.texture_seed, face, u, v, kSceneBoxTextureCell_m);
  const double coarse = FaceNoise(b.texture_seed + 1, face, u, v, kSceneBoxTextureCell_m * kCoarseTextureCells);
  const double noise = kFineTextureShare * fine + (1 - kFineTextureShare) * coarse;
  return std::clamp(static_cast<float>(b.albedo * (1 + kSceneBoxTextureAmplitude * noise)), kMinBoxAlbedo, kMaxBoxAlbedo);
}

}  // namespace

StereoRenderer::StereoRenderer(const StereoScene* scene) : scene_(scene) {}

void StereoRenderer::EnsurePattern(const ProjectorSpec& p) {
  if (pattern_dots_ == p.dot_count && pattern_fill_ == p.dot_fill && pattern_tan_h_ == std::tan(p.foi_h_rad / 2) &&
      pattern_tan_v_ == std::tan(p.foi_v_rad / 2)) {
    return;
  }
  pattern_tan_h_ = std::tan(p.foi_h_rad / 2);
  pattern_tan_v_ = std::tan(p.foi_v_rad / 2);
  pattern_res_ = kPatternTanPerPx;
  const int w = static_cast<int>(std::ceil(2 * pattern_tan_h_ / pattern_res_));
  const int h = static_cast<int>(std::ceil(2 * pattern_tan_v_ / pattern_res_));
  cv::Mat dots = cv::Mat::zeros(h, w, CV_8U);
  // Dot radius so that dot_count dots cover dot_fill of the field (in tan-angle area).
  const double radius_px = std::sqrt(p.dot_fill * w * h / (p.dot_count * CV_PI));
  cv::RNG rng(0xD075);  // the projector's fixed pattern (a diffractive element: one per device)
  constexpr int kShift = 4;
  for (int i = 0; i < p.dot_count; ++i) {
    const cv::Point c(static_cast<int>(rng.uniform(0.0, double(w)) * (1 << kShift)),
                      static_cast<int>(rng.uniform(0.0, double(h)) * (1 << kShift)));
    cv::circle(dots, c, static_cast<int>(radius_px * (1 << kShift)), cv::Scalar(255), cv::FILLED, cv::LINE_AA, kShift);
  }
  dots.convertTo(pattern_, CV_32F);
  const double mean = cv::mean(pattern_)[0];
  pattern_ *= 1.0 / std::max(mean, 1e-9);
  pattern_dots_ = p.dot_count;
  pattern_fill_ = p.dot_fill;
}

void StereoRenderer::CastView(const Vec3& centre, const double* r, const StereoSpec& spec, const Vec3& projector,
                              cv::Mat* radiance, cv::Mat* depth) {
  const StereoScene& s = *scene_;
  const int w = spec.width_px, h = spec.height_px;
  const double f = spec.FocalPx(), cx = w / 2.0, cy = h / 2.0;
  radiance->create(h, w, CV_32F);
  if (depth != nullptr) depth->create(h, w, CV_32F);
  const double e1 = PatternIrradianceAt1m(spec.projector);
  if (!ray_boxes_.empty()) BoundBoxesInView(centre, r);
  for (int v = 0; v < h; ++v) {
    auto* rad = radiance->ptr<float>(v);
    float* dep = depth != nullptr ? depth->ptr<float>(v) : nullptr;
    for (int u = 0; u < w; ++u) {
      // Ray: centre + t * d, with t the depth along the optical axis (d's optical z is 1).
      const double xn = (u + 0.5 - cx) / f, yn = (v + 0.5 - cy) / f;
      const Vec3 d{r[0] * xn + r[1] * yn + r[2], r[3] * xn + r[4] * yn + r[5], r[6] * xn + r[7] * yn + r[8]};
      if (d.z > -kMinDownward) {
        rad[u] = kSkyRadiance;
        if (dep != nullptr) dep[u] = 0;
        continue;
      }
      float box_albedo = -1;  // < 0: the ray sees the height field
      double t = MarchToSurface(s, tile_max_, centre, d);
      if (!ray_boxes_.empty()) t = NearestBoxHit(centre, d, xn, yn, t, &box_albedo);
      const Vec3 hp = centre + d * t;
      const int col = std::clamp(static_cast<int>(std::lround((hp.x - s.origin_x_m) / s.cell_m)), 0, s.albedo.cols - 1);
      const int row = std::clamp(static_cast<int>(std::lround((hp.y - s.origin_y_m) / s.cell_m)), 0, s.albedo.rows - 1);
      double irr = s.ambient_w_m2.at<float>(row, col);
      if (e1 > 0) irr += PatternIrradiance(hp, projector, r, e1, spec.projector.range_m);
      rad[u] = static_cast<float>((box_albedo >= 0 ? box_albedo : s.albedo.at<float>(row, col)) * irr);
      if (dep != nullptr) dep[u] = static_cast<float>(t);
    }
  }
}

void StereoRenderer::PrepareBoxes() {
  ray_boxes_.clear();
  for (const SceneBox& b : scene_->boxes) {
    const Vec3 ex = Rotate(b.attitude, Vec3{1, 0, 0}), ey = Rotate(b.attitude, Vec3{0, 1, 0});
    const Vec3 ez = Rotate(b.attitude, Vec3{0, 0, 1});
    ray_boxes_.push_back({&b, {ex.x, ex.y, ex.z, ey.x, ey.y, ey.z, ez.x, ez.y, ez.z}});
  }
}

void StereoRenderer::BoundBoxesInView(const Vec3& centre, const double* r) {
  constexpr double kWholeView = 1e9;  // a sphere reaching the camera's plane: every ray tests it
  for (RayBox& rb : ray_boxes_) {
    const Vec3 q = rb.box->centre_m - centre;
    const double x = r[0] * q.x + r[3] * q.y + r[6] * q.z, y = r[1] * q.x + r[4] * q.y + r[7] * q.z;
    const double z = r[2] * q.x + r[5] * q.y + r[8] * q.z, rad = BoundingRadiusM(*rb.box);
    if (z - rad <= kNearClip_m) {
      rb.xn_min = rb.yn_min = -kWholeView, rb.xn_max = rb.yn_max = kWholeView;
      continue;
    }
    // Over the sphere a / z, with a in [c - rad, c + rad] and z in [z - rad, z + rad], lies
    // between the quotients of those ends.
    const double near = z - rad, far = z + rad;
    rb.xn_min = std::min((x - rad) / near, (x - rad) / far), rb.xn_max = std::max((x + rad) / near, (x + rad) / far);
    rb.yn_min = std::min((y - rad) / near, (y - rad) / far), rb.yn_max = std::max((y + rad) / near, (y + rad) / far);
  }
}

double StereoRenderer::NearestBoxHit(const Vec3& centre, const Vec3& d, double xn, double yn, double t_surface_m,
                                     float* albedo) const {
  double best_t = t_surface_m;
  for (const RayBox& rb : ray_boxes_) {
    if (xn < rb.xn_min || xn > rb.xn_max || yn < rb.yn_min || yn > rb.yn_max) continue;  // not towards it
    const std::array<double, 9>& m = rb.world_to_box;
    const Vec3 q = centre - rb.box->centre_m;
    const double o[3] = {m[0] * q.x + m[1] * q.y + m[2] * q.z, m[3] * q.x + m[4] * q.y + m[5] * q.z,
                         m[6] * q.x + m[7] * q.y + m[8] * q.z};
    const double v[3] = {m[0] * d.x + m[1] * d.y + m[2] * d.z, m[3] * d.x + m[4] * d.y + m[5] * d.z,
                         m[6] * d.x + m[7] * d.y + m[8] * d.z};
    const double h[3] = {rb.box->half_size_m.x, rb.box->half_size_m.y, rb.box->half_size_m.z};
    double t_in = kNearClip_m, t_out = best_t;  // slabs: the ray's span inside each pair of faces
    int entry_axis = -1;
    for (int a = 0; a < 3 && t_in <= t_out; ++a) {
      if (v[a] == 0) {
        if (std::abs(o[a]) > h[a]) t_out = -1;  // parallel to the slab, outside it
        continue;
      }
      const double t0 = (-h[a] - o[a]) / v[a], t1 = (h[a] - o[a]) / v[a];
      if (std::min(t0, t1) > t_in) t_in = std::min(t0, t1), entry_axis = a;
      t_out = std::min(t_out, std::max(t0, t1));
    }
    if (entry_axis < 0 || t_in > t_out || t_in >= best_t) continue;  // missed, or starts inside the box
    best_t = t_in;
    *albedo = BoxAlbedo(*rb.box, entry_axis, Vec3{o[0] + t_in * v[0], o[1] + t_in * v[1], o[2] + t_in * v[2]});
  }
  return best_t;
}

double StereoRenderer::PatternIrradianceAt1m(const ProjectorSpec& p) const {
  if (!p.enabled || !(p.optical_power_w > 0)) return 0.0;
  // Power over the field's solid angle (a rectangle of tan half-widths a, b spans
  // 4 asin(a b / sqrt((1 + a^2)(1 + b^2))) sr).
  const double a = pattern_tan_h_, b = pattern_tan_v_;
  const double solid_angle = 4 * std::asin(a * b / std::sqrt((1 + a * a) * (1 + b * b)));
  return p.optical_power_w / solid_angle;
}

double StereoRenderer::PatternIrradiance(const Vec3& hit, const Vec3& projector, const double* r, double e1,
                                         double range_m) const {
  const Vec3 q = hit - projector;
  const double qx = r[0] * q.x + r[3] * q.y + r[6] * q.z;  // into the optical frame
  const double qy = r[1] * q.x + r[4] * q.y + r[7] * q.z;
  const double qz = r[2] * q.x + r[5] * q.y + r[8] * q.z;
  const double dist2 = Dot(q, q);
  if (!(qz > kProjectorNear_m && dist2 < range_m * range_m)) return 0.0;
  const double px = (qx / qz + pattern_tan_h_) / pattern_res_ - 0.5;
  const double py = (qy / qz + pattern_tan_v_) / pattern_res_ - 0.5;
  if (!(px >= 0 && py >= 0 && px < pattern_.cols - 1 && py < pattern_.rows - 1)) return 0.0;
  // Bilinear in the pattern.
  const int ix = static_cast<int>(px), iy = static_cast<int>(py);
  const float ax = static_cast<float>(px - ix), ay = static_cast<float>(py - iy);
  const float* p0 = pattern_.ptr<float>(iy);
  const float* p1 = pattern_.ptr<float>(iy + 1);
  const double pat = (p0[ix] * (1 - ax) + p0[ix + 1] * ax) * (1 - ay) + (p1[ix] * (1 - ax) + p1[ix + 1] * ax) * ay;
  return e1 * pat / dist2;
}

void StereoRenderer::Render(const Pose& body_pose, const StereoSpec& spec, std::uint64_t noise_seed,
                            StereoFrame* out) {
  EnsurePattern(spec.projector);
  BuildTileMax(*scene_, &tile_max_);  // the scene may have changed in place since the last pair
  PrepareBoxes();
  const std::array<double, 9> r = OpticalToWorld(body_pose.attitude);
  const Vec3 mid = body_pose.position_m + Rotate(body_pose.attitude, spec.offset_m);
  const Vec3 ex{r[0], r[3], r[6]};  // optical x in world
  const Vec3 left = mid - ex * (spec.baseline_m / 2), right = mid + ex * (spec.baseline_m / 2);
  CastView(left, r.data(), spec, mid, &radiance_l_, &out->depth_truth_m);
  CastView(right, r.data(), spec, mid, &radiance_r_, nullptr);

  // One auto-exposure for both views (the device syncs them): the left view's mean to kTargetLevel.
  const double mean = cv::mean(radiance_l_)[0];
  const double gain = std::min(kMaxGain, kTargetLevel / std::max(mean, 1e-9));
  cv::RNG rng(noise_seed);
  for (auto [rad, img] : {std::pair{&radiance_l_, &out->left}, std::pair{&radiance_r_, &out->right}}) {
    noise_.create(rad->size(), CV_32F);
    rng.fill(noise_, cv::RNG::NORMAL, 0.0, spec.noise_std);
    cv::Mat level = *rad * gain + noise_;
    level.convertTo(*img, CV_8U);  // rounds and clips to 0..255
  }
  out->focal_px = spec.FocalPx();
  out->cx_px = spec.width_px / 2.0;
  out->cy_px = spec.height_px / 2.0;
  out->baseline_m = spec.baseline_m;
  out->exposure_gain = gain;
  out->left_optical_pose.position_m = left;
  out->left_optical_pose.attitude = QuatOf(r);
}

}  // namespace swarmbox::physics
