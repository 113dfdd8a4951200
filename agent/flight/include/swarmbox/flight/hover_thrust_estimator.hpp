// HoverThrustEstimator: the collective thrust that holds the vehicle in a hover, learnt in flight
// from the vertical acceleration and the thrust that produced it (the structure of PX4's
// mc_hover_thrust_estimator/zero_order_hover_thrust_ekf: a one-state Kalman filter).
//
// Model: thrust is normalised (collective vertical thrust / the vehicle's maximum collective
// thrust, 0..1); with hover thrust h the vertical acceleration is
//     a_z = g * thrust_z / h - g            (a_z world up, gravity removed [m/s^2])
// so h = m g / T_max is the vehicle's effective mass in thrust units: a heavier load shows as a
// larger h. The state is constant between fusions (zero order) with a small process noise; a
// measurement is fused when its innovation passes a chi-square gate. When innovations keep
// failing the gate on one side (the load changed: a payload attached or released) the state
// variance is bumped so the filter re-converges within a second or two. The acceleration noise
// is learnt from the residuals (propellers, a swinging sling).
//
//   HoverThrustEstimator hte;  hte.Reset(0.5, 0.1);
//   each control step in the air: hte.Predict(dt); hte.Fuse(acc_up, thrust_z_norm, dt);
//   mass_kg = hte.hover_thrust() * max_thrust_n / g;
//
// Pure maths: no allocation, no exceptions, deterministic.
#pragma once

namespace swarmbox::flight {

struct HoverThrustParams {
  double process_noise = 0.0036;    // hover thrust process noise [1/s] (PX4 HTE_HT_NOISE)
  double init_std = 0.1;            // 1-sigma uncertainty after Reset() (PX4 HTE_HT_ERR_INIT)
  double gate_sd = 3.0;             // innovation gate [standard deviations] (PX4 HTE_ACC_GATE)
  double min_hover = 0.1;           // bounds of the estimate (normalised thrust)
  double max_hover = 0.9;
  double acc_var_init = 5.0;        // initial acceleration noise variance [(m/s^2)^2]
  double acc_var_min = 1.0;         // bounds of the learnt acceleration noise variance
  double acc_var_max = 400.0;
  double lpf_tau_s = 1.0;           // residual and signed test ratio low-pass [s]
  double noise_tau_s = 2.0;         // acceleration noise learning time constant [s]
  double offset_ratio = 0.2;        // |low-passed signed test ratio| above this: load changed
  double bump = 1e3;                // state variance bump factor on a detected change
};

struct HoverThrustStatus {
  double innovation = 0.0;          // measured - predicted a_z [m/s^2]
  double innovation_var = 0.0;      // [(m/s^2)^2]
  double test_ratio = 0.0;          // innov^2 / (gate^2 innov_var); < 1 passes
  bool fused = false;
};

class HoverThrustEstimator {
 public:
  HoverThrustEstimator() = default;
  explicit HoverThrustEstimator(const HoverThrustParams& params) : params_(params) {}

  void SetParams(const HoverThrustParams& params) { params_ = params; }
  const HoverThrustParams& params() const { return params_; }

  // Starts over from `hover_thrust` (clamped to the bounds) with 1-sigma `std` (< 0: init_std);
  // the learnt acceleration noise and the change detector restart too.
  void Reset(double hover_thrust, double std = -1.0);
  // A new prior with its uncertainty (e.g. the load announced at a payload attach): moves the
  // estimate, widens the variance to at least std^2, keeps the learnt acceleration noise.
  void SetPrior(double hover_thrust, double std);

  // Grows the state variance over dt [s].
  void Predict(double dt_s);
  // Fuses one measurement: acc_up_m_s2 = vertical acceleration, world up, gravity removed;
  // thrust_z = vertical component of the collective thrust / maximum collective thrust.
  // noise_scale >= 1 de-weights the measurement (fast climbs, drag). dt_s sizes the low-passes.
  HoverThrustStatus Fuse(double acc_up_m_s2, double thrust_z, double dt_s, double noise_scale = 1.0);

  double hover_thrust() const { return hover_; }
  double variance() const { return var_; }

 private:
  // Fuse's tail: the residual's bias, the signed test ratio's low-pass (the change detector) and
  // the acceleration noise learnt from the unbiased residual (h_meas: the measurement Jacobian).
  void TrackResidual(double residual, double signed_ratio, double h_meas, double dt_s);

  HoverThrustParams params_;
  double hover_ = 0.5;
  double var_ = 0.01;
  double acc_var_ = 5.0;
  double residual_lpf_ = 0.0;
  double ratio_lpf_ = 0.0;
};

}  // namespace swarmbox::flight
