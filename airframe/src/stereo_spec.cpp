#include "swarmbox/airframe/stereo_spec.hpp"

#include <cmath>
#include <numbers>

#include "swarmbox/airframe/yaml_read.hpp"

namespace swarmbox::airframe {
namespace {

using detail::Checked;
using detail::Nested;
using yaml::MapReader;
using yaml::Node;

Error Bad(const Node& map, const char* key, const std::string& msg) {
  return detail::InvalidAt(map, key, "stereo: " + msg);
}

void ReadProjector(MapReader& parent, ProjectorSpec* p) {
  Nested(parent, "projector", "stereo projector", false, [p](MapReader& r, const Node& n) {
    std::string pattern = "dots";
    r.Optional("enabled", &p->enabled).Optional("pattern", &pattern).Optional("dot_count", &p->dot_count);
    Checked(r, n)
        .Positive("foi_h_rad", &p->foi_h_rad, false)
        .Positive("foi_v_rad", &p->foi_v_rad, false)
        .NonNegative("optical_power_w", &p->optical_power_w)
        .Positive("dot_fill", &p->dot_fill, false)
        .Positive("range_m", &p->range_m, false);
    if (!r.ok()) return;
    if (pattern != "dots") {
      r.Fail(Bad(n, "pattern", "projector pattern must be 'dots' (a pseudo-random dot field; got '" + pattern + "')"));
    } else if (p->dot_count < 100 || p->dot_count > 100000) {
      r.Fail(Bad(n, "dot_count", "projector dot_count must be within 100..100000"));
    } else if (p->dot_fill >= 0.5) {
      r.Fail(Bad(n, "dot_fill", "projector dot_fill must be below 0.5 (dots, not a flood light)"));
    } else if (p->foi_h_rad >= std::numbers::pi * 0.9 || p->foi_v_rad >= std::numbers::pi * 0.9) {
      r.Fail(Bad(n, "foi_h_rad", "projector field of illumination must be below 0.9 pi"));
    }
  });
}

}  // namespace

double StereoSpec::FocalPx() const { return width_px / 2.0 / std::tan(hfov_rad / 2); }

Result<StereoSpec> ParseStereoSpec(const Node* node) {
  StereoSpec s;
  if (node == nullptr || node->is_null()) return s;
  MapReader r(*node, "stereo");
  s.enabled = true;
  r.Optional("enabled", &s.enabled)
      .Optional("width_px", &s.width_px)
      .Optional("height_px", &s.height_px)
      .Optional("num_disparities", &s.num_disparities)
      .Optional("offset_m", &s.offset_m);
  Checked(r, *node)
      .Positive("baseline_m", &s.baseline_m, false)
      .Positive("hfov_rad", &s.hfov_rad, false)
      .Positive("rate_hz", &s.rate_hz, false)
      .NonNegative("noise_std", &s.noise_std)
      .NonNegative("latency_min_ms", &s.latency_min_ms)
      .NonNegative("latency_max_ms", &s.latency_max_ms);
  if (r.ok()) ReadProjector(r, &s.projector);
  if (auto st = r.Finish(); !st) return st.error();
  const Node& n = *node;
  if (s.width_px < 32 || s.height_px < 32 || s.width_px > 4096 || s.height_px > 4096) {
    return Bad(n, "width_px", "size must be within 32..4096 pixels");
  }
  if (s.hfov_rad >= std::numbers::pi * 0.9) return Bad(n, "hfov_rad", "hfov_rad must be below 0.9 pi");
  if (s.baseline_m > 1.0) return Bad(n, "baseline_m", "baseline_m must be at most 1 m");
  if (s.latency_max_ms < s.latency_min_ms) return Bad(n, "latency_max_ms", "latency_max_ms must be >= latency_min_ms");
  if (s.num_disparities < 16 || s.num_disparities > 256 || s.num_disparities % 16 != 0) {
    return Bad(n, "num_disparities", "num_disparities must be a multiple of 16 within 16..256");
  }
  if (s.num_disparities >= s.width_px / 2) {
    return Bad(n, "num_disparities", "num_disparities must be below half the image width");
  }
  return s;
}

}  // namespace swarmbox::airframe
