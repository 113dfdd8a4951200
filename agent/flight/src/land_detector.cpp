#include "swarmbox/flight/land_detector.hpp"

#include <cmath>

#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {

bool LandDetector::InAir(double airborne_s, double height_m, double vz_mps) {
  if (airborne_s > params_.in_air_after_s && (height_m > params_.in_air_height_m || vz_mps < -params_.sinking_mps)) {
    in_air_ = true;
  }
  return in_air_;
}

bool LandDetector::UpdateTouchdown(double dt_s, double in_land_s, double vz_mps, double vz_cmd_mps, double thrust_n,
                                   double mass_kg) {
  const bool still = std::abs(vz_mps) < params_.vz_max_mps && vz_cmd_mps < -params_.descend_cmd_mps;
  const bool low_thrust = thrust_n < params_.low_thrust_ratio * mass_kg * kGravity_mps2;
  landed_timer_s_ = (in_land_s > params_.land_settle_s && still && low_thrust) ? landed_timer_s_ + dt_s : 0.0;
  return landed_timer_s_ > params_.trigger_time_s;
}

}  // namespace swarmbox::flight
