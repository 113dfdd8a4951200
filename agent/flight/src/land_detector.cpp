#include "swarmbox/flight/land_detector.hpp"

#include <cmath>

#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {

bool LandDetector::InAir(double airborne_s, double height_m, double vz_m_s) {
  if (airborne_s > params_.in_air_after_s && (height_m > params_.in_air_height_m || vz_m_s < -params_.sinking_m_s)) {
    in_air_ = true;
  }
  return in_air_;
}

bool LandDetector::UpdateTouchdown(double dt_s, double in_land_s, double vz_m_s, double vz_cmd_m_s, double thrust_n,
                                   double mass_kg) {
  const bool still = std::abs(vz_m_s) < params_.vz_max_m_s && vz_cmd_m_s < -params_.descend_cmd_m_s;
  const bool low_thrust = thrust_n < params_.low_thrust_ratio * mass_kg * kGravity_m_s2;
  landed_timer_s_ = (in_land_s > params_.land_settle_s && still && low_thrust) ? landed_timer_s_ + dt_s : 0.0;
  return landed_timer_s_ > params_.trigger_time_s;
}

}  // namespace swarmbox::flight
