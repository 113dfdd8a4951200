#include "swarmbox/faults/physics_plan.hpp"

#include <cmath>
#include <numbers>
#include <variant>

#include "swarmbox/faults/detail/number_format.hpp"

namespace swarmbox::faults {

bool IsPhysicsFault(const Fault& fault) {
  return std::holds_alternative<GpsDropout>(fault.action) || std::holds_alternative<GpsDegrade>(fault.action) ||
         std::holds_alternative<ImuBias>(fault.action) || std::holds_alternative<WindGust>(fault.action);
}

std::array<double, 3> GustVelocityEnu(const WindGust& gust) {
  const double from = gust.direction_deg * std::numbers::pi / 180.0;
  // To the micrometre per second, so 270 deg gives (s, 0, w), not (s, -1.8e-15, w); + 0.0 makes -0 0.
  auto um = [](double v) { return std::round(v * 1e6) / 1e6 + 0.0; };
  return {um(-gust.speed_m_s * std::sin(from)), um(-gust.speed_m_s * std::cos(from)), gust.vertical_m_s};
}

PhysicsPlan PlanPhysicsFault(const Fault& fault, const std::vector<std::string>& targets) {
  PhysicsPlan plan;
  const double duration_s =
      fault.duration_ms ? static_cast<double>(*fault.duration_ms) / 1000.0 : kUntilEndS;
  if (std::holds_alternative<GpsDropout>(fault.action)) {
    for (const std::string& t : targets) plan.apply.push_back({t, "gps_dropout", {duration_s}});
  } else if (const auto* degrade = std::get_if<GpsDegrade>(&fault.action)) {
    for (const std::string& t : targets) {
      plan.apply.push_back({t, "gps_degrade", {duration_s, degrade->h_acc_m, degrade->v_acc_m}});
    }
  } else if (const auto* bias = std::get_if<ImuBias>(&fault.action)) {
    const auto& a = bias->accel_m_s2;
    const auto& g = bias->gyro_rad_s;
    for (const std::string& t : targets) {
      plan.apply.push_back({t, "imu_bias_jump", {a[0], a[1], a[2], g[0], g[1], g[2]}});
      if (fault.duration_ms) {  // 0.0 - x: no "-0" in the argv
        plan.undo.push_back({t, "imu_bias_jump", {0.0 - a[0], 0.0 - a[1], 0.0 - a[2], 0.0 - g[0], 0.0 - g[1], 0.0 - g[2]}});
      }
    }
  } else if (const auto* gust = std::get_if<WindGust>(&fault.action)) {
    const auto v = GustVelocityEnu(*gust);
    plan.apply.push_back({"", "wind_gust", {v[0], v[1], v[2], duration_s}});
  }
  return plan;
}

std::string WorldCommandText(const WorldCommandCall& call) {
  std::string out = call.command + " " + (call.target.empty() ? "-" : call.target);
  for (double a : call.args) out += " " + detail::FormatDecimal(a);
  return out;
}

}  // namespace swarmbox::faults
