#include "swarmbox/airframe/thermal_spec.hpp"

#include <cmath>
#include <numbers>

#include "swarmbox/airframe/yaml_read.hpp"

namespace swarmbox::airframe {

double ThermalSpec::FocalPx() const { return width_px / 2.0 / std::tan(hfov_rad / 2); }

Result<ThermalSpec> ParseThermalSpec(const yaml::Node* node) {
  ThermalSpec s;
  if (node == nullptr || node->is_null()) return s;
  yaml::MapReader r(*node, "thermal");
  s.enabled = true;
  r.Optional("enabled", &s.enabled)
      .Optional("width_px", &s.width_px)
      .Optional("height_px", &s.height_px)
      .Optional("offset_m", &s.offset_m);
  detail::Checked(r, *node)
      .Positive("hfov_rad", &s.hfov_rad, false)
      .Positive("rate_hz", &s.rate_hz, false)
      .NonNegative("netd_k", &s.netd_k)
      .NonNegative("offset_std_k", &s.offset_std_k)
      .NonNegative("psf_sigma_px", &s.psf_sigma_px);
  if (auto st = r.Finish(); !st) return st.error();
  const yaml::Node& n = *node;
  auto bad = [&n](const char* key, const std::string& msg) {
    return detail::InvalidAt(n, key, "thermal: " + msg);
  };
  if (s.width_px < 16 || s.height_px < 16 || s.width_px > 2048 || s.height_px > 2048) {
    return bad("width_px", "size must be within 16..2048 pixels");
  }
  if (s.hfov_rad >= std::numbers::pi * 0.9) return bad("hfov_rad", "hfov_rad must be below 0.9 pi");
  if (s.netd_k > 1.0)
    return bad("netd_k", "netd_k must be at most 1 K (an uncooled core's NETD is tens of mK)");
  if (s.psf_sigma_px > 5.0) return bad("psf_sigma_px", "psf_sigma_px must be at most 5 pixels");
  return s;
}

}  // namespace swarmbox::airframe
