// HoverThrustModule: what feeds the hover thrust estimator (hover_thrust_estimator.hpp, the
// one-state EKF) each control step, as PX4's mc_hover_thrust_estimator module does around its
// ZeroOrderHoverThrustEkf: only in the air (the land detector's answer), with the collective
// thrust the rotors deliver (the commanded thrust through their first-order lag), and de-weighting
// fast vertical and horizontal flight (drag, prop wash) by how far the speed is over a threshold.
//
//   HoverThrustModule hover;  hover.Configure(params, ekf_params, mixer.max_thrust_n());
//   at take-off: hover.Reset(prior);       disarmed: hover.ClearThrust();
//   each step: if (hover.Update(in_air, last_thrust_n, body_z_up, acc_up, vel, dt)) mass = ...;
//
// Pure: no allocation, no exceptions, deterministic. ENU, z up; [N], [m/s], [m/s^2], [s].
#pragma once

#include "swarmbox/flight/hover_thrust_estimator.hpp"
#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {

struct HoverThrustModuleParams {
  double thrust_lag_s = 0.0;         // rotor lag applied to the thrust fed [s] (control.hover_thrust.thrust_lag_s)
  double vz_threshold_m_s = 2.0;     // de-weight above this vertical speed (PX4 HTE_VZ_THR)
  double vxy_threshold_m_s = 10.0;   // de-weight above this horizontal speed (PX4 HTE_VXY_THR)
};

class HoverThrustModule {
 public:
  // max_thrust_n: the vehicle's maximum collective thrust, normalising the thrust fed.
  void Configure(const HoverThrustModuleParams& params, const HoverThrustParams& ekf, double max_thrust_n);

  // Starts over from `hover_thrust` (take-off), with no thrust delivered yet.
  void Reset(double hover_thrust);
  // A new prior (an announced load); see HoverThrustEstimator::SetPrior.
  void SetPrior(double hover_thrust, double std) { ekf_.SetPrior(hover_thrust, std); }
  // Motors off: the rotors deliver nothing.
  void ClearThrust() { thrust_lagged_n_ = 0.0; }

  // One control step: thrust_n = the collective thrust commanded last step [N], body_z_up = the
  // world-up component of the body z axis, acc_up_m_s2 = vertical acceleration (gravity removed),
  // vel_m_s = estimated velocity. Fuses only in the air and with thrust; true when it did.
  bool Update(bool in_air, double thrust_n, double body_z_up, double acc_up_m_s2, const Vec3& vel_m_s, double dt_s);

  double hover_thrust() const { return ekf_.hover_thrust(); }
  double variance() const { return ekf_.variance(); }
  double delivered_thrust_n() const { return thrust_lagged_n_; }
  const HoverThrustEstimator& estimator() const { return ekf_; }

 private:
  HoverThrustModuleParams params_;
  HoverThrustEstimator ekf_;
  double max_thrust_n_ = 1.0;
  double thrust_lagged_n_ = 0.0;   // the commanded thrust through the rotors' lag [N]
};

}  // namespace swarmbox::flight
