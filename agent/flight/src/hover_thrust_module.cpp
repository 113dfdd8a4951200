#include "swarmbox/flight/hover_thrust_module.hpp"

#include <algorithm>
#include <cmath>

namespace swarmbox::flight {

void HoverThrustModule::Configure(const HoverThrustModuleParams& params, const HoverThrustParams& ekf,
                                  double max_thrust_n) {
  params_ = params;
  ekf_.SetParams(ekf);
  max_thrust_n_ = max_thrust_n;
}

void HoverThrustModule::Reset(double hover_thrust) {
  ekf_.Reset(hover_thrust);
  thrust_lagged_n_ = 0.0;
}

bool HoverThrustModule::Update(bool in_air, double thrust_n, double body_z_up, double acc_up_m_s2, const Vec3& vel_m_s,
                               double dt_s) {
  const double lag_s = params_.thrust_lag_s;
  thrust_lagged_n_ += (lag_s > 0.0 ? std::min(1.0, dt_s / lag_s) : 1.0) * (thrust_n - thrust_lagged_n_);
  if (!in_air || !(thrust_lagged_n_ > 0.0)) return false;
  ekf_.Predict(dt_s);
  const double thrust_z = thrust_lagged_n_ * body_z_up / max_thrust_n_;
  const double scale = std::max({1.0, std::abs(vel_m_s.z()) - params_.vz_threshold_m_s + 1.0,
                                 vel_m_s.head<2>().norm() - params_.vxy_threshold_m_s + 1.0});
  ekf_.Fuse(acc_up_m_s2, thrust_z, dt_s, scale);
  return true;
}

}  // namespace swarmbox::flight
