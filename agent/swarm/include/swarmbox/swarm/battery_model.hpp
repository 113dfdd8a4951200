// BatteryModel: a simple per-airframe energy model for the mission's `battery_low` decision.
//
//   BatteryModel battery(*BatterySpecFor("x500"));
//   battery.Step(dt_s, est.vel_m_s, payload_mass_kg);                 // every control step
//   if (battery.IsLow(distance_home_m, altitude_m, payload_mass_kg))  // -> event=battery_low
//
// Power [W] (momentum theory for the induced part, flat-plate drag for the parasitic part):
//   P = P_hover * ((m + m_payload) / m)^1.5                     hover, scaled with the lifted mass
//     + 0.5 * rho * CdA * |v_xy|^3 / eta                         forward flight (parasitic drag)
//     + (m + m_payload) * g * max(v_z, 0) / eta                  climbing
// Energy to return home: cruise at cruise_speed_m_s over the horizontal distance, then descend
// altitude_m at descent_speed_m_s (hover power), plus a fixed landing allowance.
// The battery is low when the energy left after the reserve no longer covers
// return_margin * energy-to-home, or the state of charge falls below low_fraction.
//
// Airframe figures are assumptions, documented in battery_model.cpp (x500: PX4 X500 4S 5 Ah pack;
// x8_heavy: sized from the brief). Pure: no clock, inputs and dt in.
#pragma once

#include <string_view>

#include <Eigen/Core>

#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {

struct BatterySpec {
  double capacity_wh = 0;         // usable energy of a full pack [Wh]
  double mass_kg = 0;             // airframe mass without payload [kg]
  double hover_power_w = 0;       // electrical hover power at mass_kg [W]
  double drag_area_m2 = 0;        // Cd * A for forward flight [m^2]
  double efficiency = 0.7;        // propulsive efficiency for drag and climb power [-]
  double cruise_speed_m_s = 5.0;  // speed of the flight home [m/s]
  double descent_speed_m_s = 1.0; // [m/s]
  double landing_allowance_s = 20.0;  // hover time allowed for the approach and landing [s]
  double reserve_fraction = 0.10;     // never planned into [-]
  double return_margin = 1.3;         // factor on the energy to return home [-]
  double low_fraction = 0.20;         // state of charge that is low whatever the distance [-]
};

// Known airframes: "x500", "x8_heavy". kNotFound for others (the message lists the known ones).
Result<BatterySpec> BatterySpecFor(std::string_view airframe);

class BatteryModel {
 public:
  static constexpr double kAirDensity_kg_m3 = 1.225;
  static constexpr double kGravity_m_s2 = 9.80665;

  explicit BatteryModel(const BatterySpec& spec, double initial_fraction = 1.0);

  // Electrical power at velocity v (world ENU) carrying payload_mass_kg [W].
  double Power(const Eigen::Vector3d& velocity_m_s, double payload_mass_kg) const;
  // Drains Power(...) * dt_s while `airborne`; on the ground only an idle draw (avionics, 1% of
  // hover power).
  void Step(double dt_s, const Eigen::Vector3d& velocity_m_s, double payload_mass_kg,
            bool airborne = true);

  double EnergyToHome(double distance_m, double altitude_m, double payload_mass_kg) const;  // [J]
  bool IsLow(double distance_home_m, double altitude_m, double payload_mass_kg) const;

  double fraction() const { return remaining_j_ / capacity_j_; }  // state of charge [0, 1]
  const BatterySpec& spec() const { return spec_; }

 private:
  BatterySpec spec_;
  double capacity_j_ = 0;
  double remaining_j_ = 0;
};

}  // namespace swarmbox::swarm
