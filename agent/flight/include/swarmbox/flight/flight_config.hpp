// The flight stack's configuration, from the airframe model (swarmbox/airframe/airframe.hpp: the
// file trials/airframes/<name>.yaml, parsed and validated once by the airframe library).
//
// The airframe library owns the physical part of the file; the flight stack takes from it only
// what a real companion computer would be configured with (empty mass, rotor geometry and motor
// constants for the mixer, sensor noise figures for the estimator, the payloads' slings for swing
// damping) and owns the top-level `control:` mapping (gains and limits), which it reads here from
// the parsed document (Airframe::control), strictly: unknown keys there are errors with
// file:line:col. Every key of `control:` is optional; missing ones keep PX4's x500 defaults below.
//
//   control:
//     position: {xy_p: 0.95, z_p: 1.0, vel_xy_pid: [1.8, 0.4, 0.2], vel_z_pid: [4.0, 2.0, 0.0],
//                vel_max_xy_m_s: 5, vel_max_up_m_s: 3, vel_max_down_m_s: 1.5,
//                acc_max_xy_m_s2: 3, acc_max_z_m_s2: 2, tilt_max_deg: 45,
//                thrust_min: 0.1, thrust_max: 0.9}          # fractions of the total max thrust
//     attitude: {roll_p: 6.5, pitch_p: 6.5, yaw_p: 2.8, rate_max_deg_s: [220, 220, 200]}
//     rate: {roll_pid: [0.15, 0.2, 0.003], pitch_pid: [0.15, 0.2, 0.003], yaw_pid: [0.2, 0.1, 0.0],
//            integrator_limit: [0.3, 0.3, 0.3]}
//     takeoff: {speed_m_s: 1.5}
//     land: {speed_m_s: 0.7, slow_speed_m_s: 0.3, slow_below_m: 2.0}
//     swing_damping: {enabled: true, gain: 1.0, shaper: true, full_gain_load_ratio: 0.0}
//     hover_thrust: {process_noise: 0.0036, init_std: 0.1, gate_sd: 3.0, thrust_lag_s: 0.0}
//
//   Result<airframe::Airframe> af = airframe::LoadAirframe("trials/airframes/x500.yaml");
//   Result<FlightConfig> cfg = FlightConfigFrom(*af);      // or LoadFlightConfig(path): both at once
#pragma once

#include <string>
#include <vector>

#include "swarmbox/airframe/airframe.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/flight/attitude_control.hpp"
#include "swarmbox/flight/estimator.hpp"
#include "swarmbox/flight/hover_thrust_estimator.hpp"
#include "swarmbox/flight/mixer.hpp"
#include "swarmbox/flight/position_control.hpp"
#include "swarmbox/flight/rate_control.hpp"
#include "swarmbox/flight/trajectory.hpp"

namespace swarmbox::flight {

struct SwingDampingParams {
  bool enabled = true;
  double gain = 1.0;                  // active damping, multiplies the critical-ish gain sqrt(g L)
  bool shaper = true;                 // ZVD input shaping of the position reference
  // Payload/drone mass ratio (estimated load) from which `gain` applies in full; below it the
  // gain shrinks in proportion (LoadScaledDampingGain). 0: always the full gain.
  double full_gain_load_ratio = 0.0;
};

struct FlightConfig {
  std::string airframe;               // name in the file
  std::string source;                 // file path
  double mass_kg = 0.0;               // empty vehicle [kg]
  double base_height_m = 0.0;         // body origin above the ground when landed [m]
  std::vector<RotorGeometry> rotors;
  PositionParams position;            // thrust_min_n/thrust_max_n filled from the mixer
  double thrust_min_frac = 0.1;
  double thrust_max_frac = 0.9;
  TrajectoryLimits limits;
  AttitudeGains attitude;
  RateGains rate;
  EstimatorParams estimator;
  double takeoff_speed_m_s = 1.5;
  double land_speed_m_s = 0.7;
  double land_slow_speed_m_s = 0.3;
  double land_slow_below_m = 2.0;     // height above the take-off point where landing slows [m]
  std::vector<airframe::PayloadSpec> payloads;  // the airframe's (swing damping: sling_length_m)
  SwingDampingParams swing;
  // Hover thrust estimator (PX4 HTE_HT_NOISE, HTE_HT_ERR_INIT, HTE_ACC_GATE); its bounds are
  // set by the controller from the airframe.
  HoverThrustParams hover_thrust;
  double hover_thrust_lag_s = 0.0;    // rotor lag applied to the thrust it is fed [s]
};

// kInvalidArgument (file:line:col) for a bad `control:` mapping.
Result<FlightConfig> FlightConfigFrom(const airframe::Airframe& af);
// The airframe parsed (airframe::ParseAirframe / LoadAirframe) and then FlightConfigFrom.
Result<FlightConfig> ParseFlightConfig(const yaml::Node& airframe_root, std::string source = {});
Result<FlightConfig> LoadFlightConfig(const std::string& path);

}  // namespace swarmbox::flight
