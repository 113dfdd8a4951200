#include "swarmbox/swarm/blob_features.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <opencv2/imgproc.hpp>

#include "detail/shrink_to_scale.hpp"
#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {
namespace {

constexpr int kN = kBlobPatchPx;
constexpr int kPixels = kN * kN;
constexpr double kCentre = (kN - 1) / 2.0;
constexpr double kRingM = 0.4;  // the background ring: the patch's outer band this wide
constexpr double kRingPx = kRingM * kBlobPxPerM;
// The blob grows from the most distinct pixel this close to the candidate (the first stage's
// peak is within a cell or two of a person's centre).
constexpr double kSeedRadiusM = 0.75;
// The segmentation threshold is at least this many of the ring's standard deviations above its
// mean distance: on uniform ground Otsu would split the ground's own texture.
constexpr double kRingSigmas = 3.0;
constexpr int kOtsuBins = 64;
constexpr int kTwoMeansIterations = 5;
constexpr double kM2PerPx = 1.0 / (kBlobPxPerM * kBlobPxPerM);
// The orientation histogram covers the blob's box grown by this many patch pixels (its edges).
constexpr double kBoxMarginPx = 2.0;

// Whether patch pixel k lies in the background ring (a table: every pass over the patch asks).
bool InRing(int k) {
  static const std::array<bool, kPixels> ring = [] {
    std::array<bool, kPixels> t{};
    for (int i = 0; i < kPixels; ++i) {
      t[static_cast<std::size_t>(i)] =
          std::max(std::abs(i / kN - kCentre), std::abs(i % kN - kCentre)) > kCentre - kRingPx;
    }
    return t;
  }();
  return ring[static_cast<std::size_t>(k)];
}

float F(double x) { return static_cast<float>(x); }

double Norm3(double a, double b, double c) { return std::sqrt(a * a + b * b + c * c); }

}  // namespace

double BlobFeatureExtractor::Axes::U(int k) const {
  return (k % kN - cx) * cos_a + (k / kN - cy) * sin_a;
}

double BlobFeatureExtractor::Axes::V(int k) const {
  return -(k % kN - cx) * sin_a + (k / kN - cy) * cos_a;
}

BlobFeatureExtractor::BlobFeatureExtractor()
    : l_(kPixels), a_(kPixels), b_(kPixels), distance_(kPixels), gx_(kPixels), gy_(kPixels), blob_(kPixels),
      part_(kPixels) {
  stack_.reserve(kPixels);
  members_.reserve(kPixels);
  for (std::vector<float>& r : ring_) r.reserve(kPixels);
}

void BlobFeatureExtractor::SetFrame(const cv::Mat& bgr, double pixels_per_m) {
  SWARMBOX_CHECK(bgr.type() == CV_8UC3 && !bgr.empty() && pixels_per_m > 0);
  pixels_per_m_ = pixels_per_m;
  cv::cvtColor(detail::ShrinkToScale(bgr, pixels_per_m, kBlobPxPerM, &small_, &frame_to_lab_), lab_,
               cv::COLOR_BGR2Lab);
}

// Bilinear samples of lab_ on the patch grid (kBlobPxPerM), the frame's border replicated.
void BlobFeatureExtractor::SamplePatch(const Eigen::Vector2d& centre_px) {
  const double step = pixels_per_m_ * frame_to_lab_ / kBlobPxPerM;  // lab_ pixels per patch pixel
  const double cx = (centre_px.x() + 0.5) * frame_to_lab_ - 0.5, cy = (centre_px.y() + 0.5) * frame_to_lab_ - 0.5;
  const int w = lab_.cols, h = lab_.rows;
  std::array<int, kN> x0{}, x1{};
  std::array<float, kN> fx{};
  for (int c = 0; c < kN; ++c) {  // the columns' taps, the same on every row
    const double x = std::clamp(cx + (c - kCentre) * step, 0.0, w - 1.0);
    x0[static_cast<std::size_t>(c)] = static_cast<int>(x);
    x1[static_cast<std::size_t>(c)] = std::min(x0[static_cast<std::size_t>(c)] + 1, w - 1);
    fx[static_cast<std::size_t>(c)] = F(x - x0[static_cast<std::size_t>(c)]);
  }
  float* dst[3] = {l_.data(), a_.data(), b_.data()};
  for (int r = 0; r < kN; ++r) {
    const double y = std::clamp(cy + (r - kCentre) * step, 0.0, h - 1.0);
    const int y0 = static_cast<int>(y), y1 = std::min(y0 + 1, h - 1);
    const float fy = F(y - y0);
    const cv::Vec3b* row0 = lab_.ptr<cv::Vec3b>(y0);
    const cv::Vec3b* row1 = lab_.ptr<cv::Vec3b>(y1);
    for (std::size_t c = 0; c < kN; ++c) {
      const cv::Vec3b &p00 = row0[x0[c]], &p01 = row0[x1[c]], &p10 = row1[x0[c]], &p11 = row1[x1[c]];
      for (int ch = 0; ch < 3; ++ch) {
        const float top = p00[ch] + fx[c] * static_cast<float>(p01[ch] - p00[ch]);
        const float bottom = p10[ch] + fx[c] * static_cast<float>(p11[ch] - p10[ch]);
        dst[ch][static_cast<std::size_t>(r * kN) + c] = top + fy * (bottom - top);
      }
    }
  }
}

// Central differences of L (one-sided at the patch's edge).
void BlobFeatureExtractor::Gradients() {
  for (int r = 0; r < kN; ++r) {
    const int up = std::max(r - 1, 0), down = std::min(r + 1, kN - 1);
    for (int c = 0; c < kN; ++c) {
      const int left = std::max(c - 1, 0), right = std::min(c + 1, kN - 1);
      const auto k = static_cast<std::size_t>(r * kN + c);
      gx_[k] = 0.5f * (l_[static_cast<std::size_t>(r * kN + right)] - l_[static_cast<std::size_t>(r * kN + left)]);
      gy_[k] = 0.5f * (l_[static_cast<std::size_t>(down * kN + c)] - l_[static_cast<std::size_t>(up * kN + c)]);
    }
  }
}

// The background colour (the ring's per-channel median), every pixel's Lab distance from it, and
// the ring's own mean and standard deviation of that distance.
void BlobFeatureExtractor::Background(double* ring_mean, double* ring_std) {
  const std::vector<float>* channels[3] = {&l_, &a_, &b_};
  for (std::vector<float>& r : ring_) r.clear();
  for (int k = 0; k < kPixels; ++k) {
    if (!InRing(k)) continue;
    for (int ch = 0; ch < 3; ++ch) ring_[ch].push_back((*channels[ch])[static_cast<std::size_t>(k)]);
  }
  for (int ch = 0; ch < 3; ++ch) {
    std::vector<float>& r = ring_[ch];
    std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2), r.end());
    background_[static_cast<std::size_t>(ch)] = r[r.size() / 2];
  }
  double sum = 0, sum2 = 0, n = 0;
  for (int k = 0; k < kPixels; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const double d = Norm3(l_[i] - background_[0], a_[i] - background_[1], b_[i] - background_[2]);
    distance_[i] = F(d);
    if (!InRing(k)) continue;
    sum += d;
    sum2 += d * d;
    n += 1;
  }
  *ring_mean = sum / n;
  *ring_std = std::sqrt(std::max(0.0, sum2 / n - *ring_mean * *ring_mean));
}

// Otsu's threshold on the distances inside the ring, at least the ring's mean + kRingSigmas sd.
double BlobFeatureExtractor::Threshold(double ring_mean, double ring_std) const {
  const double floor = ring_mean + kRingSigmas * ring_std;
  float top = 0;
  for (int k = 0; k < kPixels; ++k) {
    if (!InRing(k)) top = std::max(top, distance_[static_cast<std::size_t>(k)]);
  }
  if (top <= 0) return floor;
  std::array<double, kOtsuBins> hist{};
  for (int k = 0; k < kPixels; ++k) {
    if (InRing(k)) continue;
    const int bin = std::min(kOtsuBins - 1, static_cast<int>(distance_[static_cast<std::size_t>(k)] / top * kOtsuBins));
    hist[static_cast<std::size_t>(bin)] += 1;
  }
  double total = 0, moment = 0;
  for (int i = 0; i < kOtsuBins; ++i) {
    total += hist[static_cast<std::size_t>(i)];
    moment += i * hist[static_cast<std::size_t>(i)];
  }
  double below = 0, below_moment = 0, best = -1, best_bin = 0;
  for (int i = 0; i + 1 < kOtsuBins; ++i) {
    below += hist[static_cast<std::size_t>(i)];
    below_moment += i * hist[static_cast<std::size_t>(i)];
    if (below <= 0 || below >= total) continue;
    const double m0 = below_moment / below, m1 = (moment - below_moment) / (total - below);
    const double between = below * (total - below) * (m0 - m1) * (m0 - m1);
    if (between > best) {
      best = between;
      best_bin = i;
    }
  }
  return std::max(floor, (best_bin + 1) * top / kOtsuBins);
}

// The 8-connected region of distances above `threshold` grown from the most distinct pixel within
// kSeedRadiusM of the candidate; false when there is none.
bool BlobFeatureExtractor::GrowBlob(double threshold) {
  std::fill(blob_.begin(), blob_.end(), std::uint8_t{0});
  const double seed_r2 = std::pow(kSeedRadiusM * kBlobPxPerM, 2);
  int seed = -1;
  double best = threshold;
  const int lo = static_cast<int>(kCentre - kSeedRadiusM * kBlobPxPerM), hi = kN - 1 - lo;
  for (int r = lo; r <= hi; ++r) {
    for (int c = lo; c <= hi; ++c) {
      const int k = r * kN + c;
      if (std::pow(r - kCentre, 2) + std::pow(c - kCentre, 2) > seed_r2 || distance_[static_cast<std::size_t>(k)] <= best) {
        continue;
      }
      best = distance_[static_cast<std::size_t>(k)];
      seed = k;
    }
  }
  if (seed < 0) return false;
  stack_.clear();
  members_.clear();
  stack_.push_back(seed);
  members_.push_back(seed);
  blob_[static_cast<std::size_t>(seed)] = 1;
  while (!stack_.empty()) {
    const int k = stack_.back();
    stack_.pop_back();
    const int r = k / kN, c = k % kN;
    for (int nr = std::max(r - 1, 0); nr <= std::min(r + 1, kN - 1); ++nr) {
      for (int nc = std::max(c - 1, 0); nc <= std::min(c + 1, kN - 1); ++nc) {
        const auto nk = static_cast<std::size_t>(nr * kN + nc);
        if (blob_[nk] || distance_[nk] <= threshold) continue;
        blob_[nk] = 1;
        stack_.push_back(nr * kN + nc);
        members_.push_back(nr * kN + nc);
      }
    }
  }
  return true;
}

// A blob pixel with a 4-neighbour outside the blob or on the patch's edge.
bool BlobFeatureExtractor::OnBoundary(int k) const {
  const int r = k / kN, c = k % kN;
  if (r == 0 || c == 0 || r == kN - 1 || c == kN - 1) return true;
  return !blob_[static_cast<std::size_t>(k - 1)] || !blob_[static_cast<std::size_t>(k + 1)] ||
         !blob_[static_cast<std::size_t>(k - kN)] || !blob_[static_cast<std::size_t>(k + kN)];
}

BlobFeatureExtractor::Moments BlobFeatureExtractor::BlobMoments() const {
  Moments m;
  for (int k : members_) {
    const auto i = static_cast<std::size_t>(k);
    const double x = k % kN, y = k / kN;
    m.n += 1;
    m.x += x;
    m.y += y;
    m.xx += x * x;
    m.yy += y * y;
    m.xy += x * y;
    const double lab[3] = {l_[i], a_[i], b_[i]};
    for (std::size_t ch = 0; ch < 3; ++ch) {
      m.lab[ch] += lab[ch];
      m.lab2[ch] += lab[ch] * lab[ch];
    }
    m.distance += distance_[i];
  }
  return m;
}

// Principal axes from the second moments; extents along them over the blob's pixels.
BlobFeatureExtractor::Axes BlobFeatureExtractor::PrincipalAxes(const Moments& m) const {
  Axes ax;
  ax.cx = m.x / m.n;
  ax.cy = m.y / m.n;
  const double cxx = m.xx / m.n - ax.cx * ax.cx, cyy = m.yy / m.n - ax.cy * ax.cy, cxy = m.xy / m.n - ax.cx * ax.cy;
  const double angle = 0.5 * std::atan2(2 * cxy, cxx - cyy);
  ax.cos_a = std::cos(angle);
  ax.sin_a = std::sin(angle);
  const double half_trace = 0.5 * (cxx + cyy);
  const double disc = std::sqrt(std::max(0.0, half_trace * half_trace - (cxx * cyy - cxy * cxy)));
  // The full axes of the ellipse with these moments (a uniform ellipse: variance = (axis / 4)^2).
  ax.major_px = 4 * std::sqrt(std::max(0.0, half_trace + disc));
  ax.minor_px = 4 * std::sqrt(std::max(0.0, half_trace - disc));
  ax.u_min = ax.v_min = 1e9;
  ax.u_max = ax.v_max = -1e9;
  for (int k : members_) {
    const double u = ax.U(k), v = ax.V(k);
    ax.u_min = std::min(ax.u_min, u);
    ax.u_max = std::max(ax.u_max, u);
    ax.v_min = std::min(ax.v_min, v);
    ax.v_max = std::max(ax.v_max, v);
  }
  return ax;
}

// Area, axes, elongation, extent, compactness, share of the patch's edge, centroid offset.
void BlobFeatureExtractor::ShapeFeatures(const Moments& m, const Axes& ax, float*& out) const {
  double perimeter = 0, edge = 0;
  for (int k : members_) {
    perimeter += OnBoundary(k) ? 1 : 0;
    const int r = k / kN, c = k % kN;
    edge += (r == 0 || c == 0 || r == kN - 1 || c == kN - 1) ? 1 : 0;
  }
  const double box = (ax.u_max - ax.u_min + 1) * (ax.v_max - ax.v_min + 1);
  *out++ = F(m.n * kM2PerPx);
  *out++ = F(ax.major_px / kBlobPxPerM);
  *out++ = F(ax.minor_px / kBlobPxPerM);
  *out++ = F(ax.minor_px / std::max(ax.major_px, 1e-6));
  *out++ = F(m.n / box);
  *out++ = F(perimeter * perimeter / (4 * std::numbers::pi * m.n));
  *out++ = F(edge / (4.0 * kN));
  *out++ = F(std::hypot(ax.cx - kCentre, ax.cy - kCentre) / kBlobPxPerM);
}

// Mean Lab, its difference from the background, Lab spread, contrast, threshold, ring statistics.
void BlobFeatureExtractor::ColourFeatures(const Moments& m, double threshold, double ring_mean, double ring_std,
                                          float*& out) const {
  for (std::size_t ch = 0; ch < 3; ++ch) *out++ = F(m.lab[ch] / m.n);
  for (std::size_t ch = 0; ch < 3; ++ch) *out++ = F(m.lab[ch] / m.n - background_[ch]);
  for (std::size_t ch = 0; ch < 3; ++ch) {
    const double mean = m.lab[ch] / m.n;
    *out++ = F(std::sqrt(std::max(0.0, m.lab2[ch] / m.n - mean * mean)));
  }
  *out++ = F(m.distance / m.n / std::max(threshold, 1e-6));
  *out++ = F(threshold);
  *out++ = F(ring_mean);
  *out++ = F(ring_std);
}

// Width [m] and colour distance from the blob's mean of kBlobProfileBins slices across the major
// axis, the slice most unlike the blob first.
void BlobFeatureExtractor::ProfileFeatures(const Moments& m, const Axes& ax, float*& out) const {
  std::array<double, kBlobProfileBins> count{}, width{}, distance{};
  std::array<std::array<double, 3>, kBlobProfileBins> lab{};
  const double length = ax.u_max - ax.u_min + 1;
  for (int k : members_) {
    const auto i = static_cast<std::size_t>(k);
    const auto bin = static_cast<std::size_t>(
        std::min(kBlobProfileBins - 1, static_cast<int>((ax.U(k) - ax.u_min) / length * kBlobProfileBins)));
    count[bin] += 1;
    lab[bin][0] += l_[i];
    lab[bin][1] += a_[i];
    lab[bin][2] += b_[i];
  }
  for (std::size_t b = 0; b < count.size(); ++b) {
    width[b] = count[b] / (length / kBlobProfileBins) / kBlobPxPerM;
    if (count[b] <= 0) continue;
    distance[b] = Norm3(lab[b][0] / count[b] - m.lab[0] / m.n, lab[b][1] / count[b] - m.lab[1] / m.n,
                        lab[b][2] / count[b] - m.lab[2] / m.n);
  }
  if (distance.back() > distance.front()) {
    std::reverse(width.begin(), width.end());
    std::reverse(distance.begin(), distance.end());
  }
  for (double w : width) *out++ = F(w);
  for (double d : distance) *out++ = F(d);
}

// Two-means of the blob's colours, seeded with the mean and the pixel farthest from it: each
// blob pixel's part into part_, the parts' centres into *centre; returns the parts' sizes.
std::array<double, 2> BlobFeatureExtractor::TwoMeans(const Moments& m, Colours* centre) {
  Colours& c = *centre;
  c[0] = {m.lab[0] / m.n, m.lab[1] / m.n, m.lab[2] / m.n};
  auto d2 = [&](std::size_t i, const std::array<double, 3>& x) {
    return std::pow(l_[i] - x[0], 2) + std::pow(a_[i] - x[1], 2) + std::pow(b_[i] - x[2], 2);
  };
  double far = -1;
  for (int k : members_) {
    const auto i = static_cast<std::size_t>(k);
    if (d2(i, c[0]) <= far) continue;
    far = d2(i, c[0]);
    c[1] = {l_[i], a_[i], b_[i]};
  }
  std::array<double, 2> n{};
  for (int it = 0; it < kTwoMeansIterations; ++it) {
    Colours sum{};
    n = {0, 0};
    for (int k : members_) {
      const auto i = static_cast<std::size_t>(k);
      const std::size_t p = d2(i, c[1]) < d2(i, c[0]) ? 1 : 0;
      part_[i] = static_cast<std::uint8_t>(p);
      n[p] += 1;
      sum[p] = {sum[p][0] + l_[i], sum[p][1] + a_[i], sum[p][2] + b_[i]};
    }
    for (std::size_t p = 0; p < 2; ++p) {
      for (std::size_t ch = 0; ch < 3 && n[p] > 0; ++ch) c[p][ch] = sum[p][ch] / n[p];
    }
  }
  return n;
}

// The two colour parts of the blob (TwoMeans): the smaller part's share of the blob, the parts'
// colour distance, the smaller part's position along the major axis (|u| / major: a head or the
// legs sit at an end) and its spread [m].
void BlobFeatureExtractor::PartFeatures(const Moments& m, const Axes& ax, float*& out) {
  Colours centre{};
  const std::array<double, 2> n = TwoMeans(m, &centre);
  const std::size_t minor = n[1] < n[0] ? 1 : 0;
  double su = 0, sx = 0, sy = 0, sxx = 0, syy = 0;
  for (int k : members_) {
    if (part_[static_cast<std::size_t>(k)] != minor) continue;
    const double x = k % kN, y = k / kN;
    su += ax.U(k);
    sx += x;
    sy += y;
    sxx += x * x;
    syy += y * y;
  }
  const double nm = std::max(n[minor], 1.0);
  const double spread = std::sqrt(std::max(0.0, sxx / nm - (sx / nm) * (sx / nm) + syy / nm - (sy / nm) * (sy / nm)));
  *out++ = F(n[minor] / m.n);
  *out++ = F(Norm3(centre[0][0] - centre[1][0], centre[0][1] - centre[1][1], centre[0][2] - centre[1][2]));
  *out++ = F(std::abs(su / nm) / std::max(ax.major_px, 1e-6));
  *out++ = F(spread / kBlobPxPerM);
  // Each part's colour against the ground (a shadow is the ground's colour, darker).
  for (const std::size_t p : {minor, 1 - minor}) {
    for (std::size_t ch = 0; ch < 3; ++ch) *out++ = F(centre[p][ch] - background_[ch]);
  }
}

// The gradient-orientation histogram over the blob's box relative to its major axis (unsigned,
// magnitude-weighted, normalised), the mean gradient inside the blob, on its boundary and on the
// ring, and the share of the patch's centre that is foreground outside the blob.
void BlobFeatureExtractor::EdgeFeatures(const Axes& ax, double threshold, float*& out) const {
  std::array<double, kBlobOrientationBins> hist{};
  double total = 0, inner = 0, inner_n = 0, boundary = 0, boundary_n = 0, ring = 0, ring_n = 0, other = 0, centre_n = 0;
  const double axis_deg = std::atan2(ax.sin_a, ax.cos_a) * 180.0 / std::numbers::pi;
  for (int k = 0; k < kPixels; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const float mag = std::sqrt(gx_[i] * gx_[i] + gy_[i] * gy_[i]);
    const bool in_ring = InRing(k);
    ring += in_ring ? mag : 0;
    ring_n += in_ring ? 1 : 0;
    centre_n += in_ring ? 0 : 1;
    other += !in_ring && !blob_[i] && distance_[i] > threshold ? 1 : 0;
    if (blob_[i]) {
      const bool b = OnBoundary(k);
      (b ? boundary : inner) += mag;
      (b ? boundary_n : inner_n) += 1;
    }
    const double u = ax.U(k), v = ax.V(k);
    if (u < ax.u_min - kBoxMarginPx || u > ax.u_max + kBoxMarginPx || v < ax.v_min - kBoxMarginPx ||
        v > ax.v_max + kBoxMarginPx || mag <= 0) {
      continue;
    }
    double a = cv::fastAtan2(gy_[i], gx_[i]) - axis_deg;  // [deg], within 0.3 deg
    a -= 180.0 * std::floor(a / 180.0);                    // unsigned: [0, 180)
    const int bin = std::min(kBlobOrientationBins - 1, static_cast<int>(a / 180.0 * kBlobOrientationBins));
    hist[static_cast<std::size_t>(bin)] += mag;
    total += mag;
  }
  for (double h : hist) *out++ = F(total > 0 ? h / total : 0.0);
  *out++ = F(inner / std::max(inner_n, 1.0));
  *out++ = F(boundary / std::max(boundary_n, 1.0));
  *out++ = F(ring / std::max(ring_n, 1.0));
  *out++ = F(other / std::max(centre_n, 1.0));
}

void BlobFeatureExtractor::Extract(const Eigen::Vector2d& centre_px, float* out) {
  SWARMBOX_CHECK(!lab_.empty());
  SamplePatch(centre_px);
  Gradients();
  double ring_mean = 0, ring_std = 0;
  Background(&ring_mean, &ring_std);
  const double threshold = Threshold(ring_mean, ring_std);
  float* w = out;
  if (!GrowBlob(threshold)) {  // nothing stands out near the candidate
    std::fill(out, out + kBlobFeatures, 0.0f);
    out[kBlobFeatures - 1] = F(pixels_per_m_);
    return;
  }
  *w++ = 1.0f;
  const Moments m = BlobMoments();
  const Axes ax = PrincipalAxes(m);
  ShapeFeatures(m, ax, w);
  ColourFeatures(m, threshold, ring_mean, ring_std, w);
  ProfileFeatures(m, ax, w);
  PartFeatures(m, ax, w);
  EdgeFeatures(ax, threshold, w);
  *w++ = F(pixels_per_m_);
  SWARMBOX_CHECK(w - out == kBlobFeatures);
}

}  // namespace swarmbox::swarm
