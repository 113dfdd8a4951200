#include "swarmbox/swarm/battery_model.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace swarmbox::swarm {

Result<BatterySpec> BatterySpecFor(std::string_view airframe) {
  BatterySpec s;
  if (airframe == "x500") {
    // Holybro X500 V2 with a 4S 5000 mAh pack: 74 Wh, 80% usable = 59 Wh. Hover power from
    // momentum theory: T = 20.2 N on four 10" discs (A = 0.203 m^2), P_ideal = T^1.5 /
    // sqrt(2 rho A) = 129 W, figure of merit 0.65 -> 200 W (about 18 min of hover).
    s.capacity_wh = 59.0;
    s.mass_kg = 2.0643;  // trials/airframes/x500.yaml
    s.hover_power_w = 200.0;
    s.drag_area_m2 = 0.1;
    s.cruise_speed_m_s = 5.0;
    s.descent_speed_m_s = 1.0;
    return s;
  }
  if (airframe == "x8_heavy") {
    // 120 kg coaxial X8, 1.2 m props (four coaxial pairs, 4.5 m^2 of disc): P_ideal ~ 12 kW,
    // figure of merit 0.65 and a 1.28 coaxial loss -> 24 kW empty; a 20 kWh pack (assumption)
    // gives ~50 min empty and ~23 min with the 80 kg stretcher ((200/120)^1.5 = 2.15x).
    s.capacity_wh = 20000.0;
    s.mass_kg = 120.0;  // trials/airframes/x8_heavy.yaml
    s.hover_power_w = 24000.0;
    s.drag_area_m2 = 2.0;  // body_drag_coefficient 1.2 = 0.5 rho CdA
    s.cruise_speed_m_s = 4.0;
    s.descent_speed_m_s = 0.8;
    s.landing_allowance_s = 40.0;
    return s;
  }
  return Error(ErrorCode::kNotFound, "no battery model for airframe '" + std::string(airframe) +
                                         "' (known: x500, x8_heavy)");
}

BatteryModel::BatteryModel(const BatterySpec& spec, double initial_fraction)
    : spec_(spec), capacity_j_(spec.capacity_wh * 3600.0) {
  SWARMBOX_CHECK(spec_.capacity_wh > 0 && spec_.mass_kg > 0 && spec_.hover_power_w > 0);
  SWARMBOX_CHECK(spec_.efficiency > 0 && spec_.cruise_speed_m_s > 0 && spec_.descent_speed_m_s > 0);
  SWARMBOX_CHECK(initial_fraction >= 0 && initial_fraction <= 1);
  remaining_j_ = capacity_j_ * initial_fraction;
}

double BatteryModel::Power(const Eigen::Vector3d& v, double payload_mass_kg) const {
  const double m = spec_.mass_kg + std::max(0.0, payload_mass_kg);
  const double hover = spec_.hover_power_w * std::pow(m / spec_.mass_kg, 1.5);
  const double v_xy = v.head<2>().norm();
  const double drag = 0.5 * kAirDensity_kg_m3 * spec_.drag_area_m2 * v_xy * v_xy * v_xy / spec_.efficiency;
  const double climb = m * kGravity_m_s2 * std::max(0.0, v.z()) / spec_.efficiency;
  return hover + drag + climb;
}

void BatteryModel::Step(double dt_s, const Eigen::Vector3d& velocity_m_s, double payload_mass_kg,
                        bool airborne) {
  SWARMBOX_CHECK(dt_s >= 0);
  const double p = airborne ? Power(velocity_m_s, payload_mass_kg) : 0.01 * spec_.hover_power_w;
  remaining_j_ = std::max(0.0, remaining_j_ - p * dt_s);
}

double BatteryModel::EnergyToHome(double distance_m, double altitude_m, double payload_mass_kg) const {
  const double cruise_s = std::max(0.0, distance_m) / spec_.cruise_speed_m_s;
  const double descent_s = std::max(0.0, altitude_m) / spec_.descent_speed_m_s;
  const double p_cruise = Power({spec_.cruise_speed_m_s, 0, 0}, payload_mass_kg);
  const double p_hover = Power({0, 0, 0}, payload_mass_kg);
  return p_cruise * cruise_s + p_hover * (descent_s + spec_.landing_allowance_s);
}

bool BatteryModel::IsLow(double distance_home_m, double altitude_m, double payload_mass_kg) const {
  if (fraction() < spec_.low_fraction) return true;
  const double usable = remaining_j_ - spec_.reserve_fraction * capacity_j_;
  return usable < spec_.return_margin * EnergyToHome(distance_home_m, altitude_m, payload_mass_kg);
}

}  // namespace swarmbox::swarm
