#include "swarmbox/flight/hover_thrust_estimator.hpp"

#include <algorithm>
#include <cmath>

#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {

void HoverThrustEstimator::Reset(double hover_thrust, double std) {
  hover_ = std::clamp(hover_thrust, params_.min_hover, params_.max_hover);
  const double s = std >= 0.0 ? std : params_.init_std;
  var_ = s * s;
  acc_var_ = params_.acc_var_init;
  residual_lpf_ = 0.0;
  ratio_lpf_ = 0.0;
}

void HoverThrustEstimator::SetPrior(double hover_thrust, double std) {
  hover_ = std::clamp(hover_thrust, params_.min_hover, params_.max_hover);
  var_ = std::max(var_, std * std);
  residual_lpf_ = 0.0;
  ratio_lpf_ = 0.0;
}

void HoverThrustEstimator::Predict(double dt_s) {
  if (!(dt_s > 0.0)) return;
  // Zero-order model: the state stays, its variance grows (PX4 uses q dt^2).
  var_ += params_.process_noise * params_.process_noise * dt_s * dt_s;
}

void HoverThrustEstimator::TrackResidual(double residual, double signed_ratio, double h_meas, double dt_s) {
  // Low-passed residual (its bias) and signed test ratio (the change detector).
  const double a = dt_s / (params_.lpf_tau_s + dt_s);
  residual_lpf_ += a * (residual - residual_lpf_);
  ratio_lpf_ += a * (std::clamp(signed_ratio, -1.0, 1.0) - ratio_lpf_);

  // Learn the acceleration noise from the unbiased residual.
  const double b = dt_s / (params_.noise_tau_s + dt_s);
  const double res = residual - residual_lpf_;
  acc_var_ = std::clamp((1.0 - b) * acc_var_ + b * (res * res + h_meas * var_ * h_meas), params_.acc_var_min,
                        params_.acc_var_max);
}

HoverThrustStatus HoverThrustEstimator::Fuse(double acc_up_m_s2, double thrust_z, double dt_s,
                                             double noise_scale) {
  HoverThrustStatus st;
  if (!std::isfinite(acc_up_m_s2) || !std::isfinite(thrust_z) || !(dt_s > 0.0) || !(thrust_z > 0.0)) {
    return st;
  }
  const double g = kGravity_m_s2;
  const double scale = std::max(1.0, noise_scale);
  // Linearised measurement: d a_z / d h = -g thrust / h^2.
  const double h_meas = -g * thrust_z / (hover_ * hover_);
  const double r = acc_var_ * scale * scale;
  const double innov_var = std::max(h_meas * var_ * h_meas + r, r);
  const double innov = acc_up_m_s2 - (g * thrust_z / hover_ - g);
  const double k = var_ * h_meas / innov_var;
  const double ratio = innov * innov / (params_.gate_sd * params_.gate_sd * innov_var);

  double residual = innov;
  if (ratio < 1.0) {
    hover_ = std::clamp(hover_ + k * innov, params_.min_hover, params_.max_hover);
    var_ = std::clamp((1.0 - k * h_meas) * var_, 1e-10, 1.0);
    residual = acc_up_m_s2 - (g * thrust_z / hover_ - g);
    st.fused = true;
  } else if (std::abs(ratio_lpf_) > params_.offset_ratio) {
    // Measurements rejected on one side for a while: the hover thrust jumped (load change) or the
    // filter diverged. Widen the variance so the gate opens again.
    var_ = std::min(1.0, var_ + params_.bump * params_.process_noise * params_.process_noise * dt_s);
  }
  TrackResidual(residual, innov >= 0.0 ? ratio : -ratio, h_meas, dt_s);
  st.innovation = innov;
  st.innovation_var = innov_var;
  st.test_ratio = ratio;
  return st;
}

}  // namespace swarmbox::flight
