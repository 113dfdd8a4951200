#include "swarmbox/swarm/thermal_evidence.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace swarmbox::swarm {

namespace {

float Quantile(std::vector<float>& v, double q) {
  const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<std::size_t>(k)];
}

}  // namespace

std::optional<double> ThermalContrastAt(const ThermalView& view, const Eigen::Vector3d& point_m,
                                        double radius_m) {
  if (view.kelvin.empty() || view.kelvin.type() != CV_32F || !(radius_m > 0)) return std::nullopt;
  const std::optional<Eigen::Vector2d> px = ProjectToPixel(point_m, view.k, view.pose);
  if (!px) return std::nullopt;
  const double range = (point_m - view.pose.position_m).norm();
  const double r_px = radius_m * view.k.fx_px / std::max(range, 1e-3);
  if (r_px < 0.5) return std::nullopt;
  const double outer = 3.4 * r_px, inner = 1.7 * r_px;
  const int x0 = static_cast<int>(std::floor(px->x() - outer)),
            x1 = static_cast<int>(std::ceil(px->x() + outer));
  const int y0 = static_cast<int>(std::floor(px->y() - outer)),
            y1 = static_cast<int>(std::ceil(px->y() + outer));
  if (x0 < 0 || y0 < 0 || x1 >= view.kelvin.cols || y1 >= view.kelvin.rows) return std::nullopt;
  std::vector<float> disc, ring;
  for (int y = y0; y <= y1; ++y) {
    const float* row = view.kelvin.ptr<float>(y);
    for (int x = x0; x <= x1; ++x) {
      const double d = std::hypot(x + 0.5 - px->x(), y + 0.5 - px->y());
      if (d <= r_px) {
        disc.push_back(row[x]);
      } else if (d >= inner && d <= outer) {
        ring.push_back(row[x]);
      }
    }
  }
  if (disc.empty() || ring.size() < 8) return std::nullopt;
  return static_cast<double>(Quantile(disc, 0.98)) - static_cast<double>(Quantile(ring, 0.5));
}

double ThermalEvidence::Fuse(double confidence, double contrast_k) const {
  const double p = std::clamp(confidence, 1e-6, 1 - 1e-6);
  const double z = colour_weight * std::log(p / (1 - p)) +
                   slope_per_k * std::clamp(contrast_k, kMinContrastK, kMaxContrastK) + bias;
  return 1.0 / (1.0 + std::exp(-z));
}

Result<ThermalEvidence> ParseThermalEvidence(const yaml::Node& root) {
  const yaml::Node* n = root.Find("thermal_evidence");
  if (n == nullptr)
    return Error(ErrorCode::kInvalidArgument, "thermal evidence: no `thermal_evidence:` mapping",
                 root.Where());
  ThermalEvidence e;
  yaml::MapReader r(*n, "thermal_evidence");
  r.Required("colour_weight", &e.colour_weight)
      .Required("slope_per_k", &e.slope_per_k)
      .Required("bias", &e.bias)
      .Required("radius_m", &e.radius_m);
  (void)r.Child("fit");  // provenance: seeds, counts, figures (read past)
  if (auto s = r.Finish(); !s) return s.error();
  if (!(e.slope_per_k >= 0 && e.slope_per_k < 5)) {
    return Error(ErrorCode::kInvalidArgument, "thermal evidence: slope_per_k must be within 0..5",
                 n->Where());
  }
  if (!(e.radius_m > 0.1 && e.radius_m < 3)) {
    return Error(ErrorCode::kInvalidArgument, "thermal evidence: radius_m must be within 0.1..3", n->Where());
  }
  if (!(e.colour_weight > 0 && e.colour_weight < 5) || !(std::abs(e.bias) < 20)) {
    return Error(ErrorCode::kInvalidArgument,
                 "thermal evidence: colour_weight must be within 0..5 and |bias| below 20", n->Where());
  }
  return e;
}

}  // namespace swarmbox::swarm
