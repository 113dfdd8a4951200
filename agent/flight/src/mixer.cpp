#include "swarmbox/flight/mixer.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Dense>

namespace swarmbox::flight {

namespace {

bool ValidRotor(const RotorGeometry& r) {
  return r.motor_constant > 0.0 && r.max_rot_velocity > 0.0 && r.moment_constant >= 0.0 &&
         (r.spin_dir == 1 || r.spin_dir == -1) && r.pos_m.allFinite();
}

}  // namespace

Result<Mixer> Mixer::Create(const std::vector<RotorGeometry>& rotors) {
  const std::size_t n = rotors.size();
  if (n < 4 || n > kMaxRotors) {
    return Error(ErrorCode::kInvalidArgument,
                 "mixer needs 4.." + std::to_string(kMaxRotors) + " rotors, got " + std::to_string(n));
  }
  Mixer m;
  m.n_ = n;
  m.b_.resize(4, static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) {
    const RotorGeometry& r = rotors[i];
    if (!ValidRotor(r)) {
      return Error(ErrorCode::kInvalidArgument,
                   "rotor " + std::to_string(i) +
                       ": needs motor_constant > 0, max_rot_velocity > 0, moment_constant >= 0 and "
                       "direction +1/-1");
    }
    const auto c = static_cast<Eigen::Index>(i);
    // Thrust T along body +z at r: torque = r x (0, 0, T) = (y T, -x T, 0); reaction on z.
    m.b_(0, c) = r.pos_m.y();
    m.b_(1, c) = -r.pos_m.x();
    m.b_(2, c) = -static_cast<double>(r.spin_dir) * r.moment_constant;
    m.b_(3, c) = 1.0;
    m.max_thrust_[i] = r.motor_constant * r.max_rot_velocity * r.max_rot_velocity;
    m.inv_k_wmax2_[i] = 1.0 / m.max_thrust_[i];
    m.max_total_thrust_n_ += m.max_thrust_[i];
    m.torque_scale_nm_ += 0.5 * m.max_thrust_[i] *
                          Vec3(std::abs(m.b_(0, c)), std::abs(m.b_(1, c)), std::abs(m.b_(2, c)));
  }
  if (auto s = m.Allocate(); !s) return s.error();
  return m;
}

Status Mixer::Allocate() {
  // Pseudo-inverse through a complete orthogonal decomposition (rank-revealing).
  const Eigen::MatrixXd b = b_;
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(b);
  if (cod.rank() < 4) {
    return Error(ErrorCode::kInvalidArgument,
                 "rotor geometry cannot control roll, pitch, yaw and thrust independently (rank " +
                     std::to_string(cod.rank()) + " < 4): check positions and spin directions");
  }
  const Eigen::MatrixXd pinv = cod.pseudoInverse();  // n x 4
  for (std::size_t i = 0; i < n_; ++i) {
    for (int a = 0; a < 4; ++a) alloc_[i][static_cast<std::size_t>(a)] = pinv(static_cast<Eigen::Index>(i), a);
  }
  return Ok{};
}

MixerOutput Mixer::Mix(const Vec3& torque_nm, double thrust_n) const {
  MixerOutput out;
  Shares sh;
  const double t = std::isfinite(thrust_n) ? std::clamp(thrust_n, 0.0, max_total_thrust_n_) : 0.0;
  const Vec3 tq = torque_nm.allFinite() ? torque_nm : Vec3::Zero();
  for (std::size_t i = 0; i < n_; ++i) {
    sh.rp[i] = alloc_[i][0] * tq.x() + alloc_[i][1] * tq.y();
    sh.yaw[i] = alloc_[i][2] * tq.z();
    sh.col[i] = alloc_[i][3] * t;
  }
  out.thrust_saturated = thrust_n > max_total_thrust_n_;
  // Priorities: roll/pitch first (scaled down when it cannot fit), then the collective (shifted
  // so roll/pitch fit), then yaw (what still fits).
  const double rp_scale = RollPitchScale(sh);
  const double shift = CollectiveShift(sh, rp_scale);
  if (shift != 0.0) out.thrust_saturated = true;
  const double yaw_scale = YawScale(sh, rp_scale, shift);
  for (std::size_t i = 0; i < n_; ++i) {
    const double ti = std::clamp(sh.col[i] + rp_scale * sh.rp[i] + shift + yaw_scale * sh.yaw[i], 0.0, max_thrust_[i]);
    out.thrust_n[i] = ti;
    out.u[i] = std::sqrt(ti * inv_k_wmax2_[i]);
  }
  if (rp_scale < 1.0) {
    for (int a = 0; a < 2; ++a) {
      out.sat_positive[static_cast<std::size_t>(a)] = tq[a] > 0.0;
      out.sat_negative[static_cast<std::size_t>(a)] = tq[a] < 0.0;
    }
  }
  if (yaw_scale < 1.0) {
    out.sat_positive[2] = tq.z() > 0.0;
    out.sat_negative[2] = tq.z() < 0.0;
  }
  return out;
}

double Mixer::RollPitchScale(const Shares& sh) const {
  // 1. Roll/pitch: if the spread does not fit in [0, Tmax] at all, scale it down.
  double rp_scale = 1.0;
  for (std::size_t i = 0; i < n_; ++i) {
    // Need rp[i] + c in [0, Tmax_i] for some common collective c; conservative test per rotor pair
    // is done below through the shift; here bound each rotor's swing by its own range.
    const double swing = std::abs(sh.rp[i]);
    if (swing > 0.5 * max_thrust_[i]) rp_scale = std::min(rp_scale, 0.5 * max_thrust_[i] / swing);
  }
  return rp_scale;
}

double Mixer::CollectiveShift(const Shares& sh, double rp_scale) const {
  // 2. Collective shift so roll/pitch fit: find the interval of shifts s (added as s * col share).
  double lo = -1e18, hi = 1e18;  // feasible extra collective factor bounds on shift d [N per rotor]
  for (std::size_t i = 0; i < n_; ++i) {
    const double base = sh.col[i] + rp_scale * sh.rp[i];
    lo = std::max(lo, -base);                    // base + d >= 0
    hi = std::min(hi, max_thrust_[i] - base);    // base + d <= Tmax
  }
  if (lo > hi) return 0.5 * (lo + hi);  // cannot fit exactly (only after rp scaling rounding): split
  return std::clamp(0.0, lo, hi);
}

double Mixer::YawScale(const Shares& sh, double rp_scale, double shift) const {
  // 3. Yaw: the largest fraction of the yaw share that still fits.
  double yaw_scale = 1.0;
  for (std::size_t i = 0; i < n_; ++i) {
    const double base = sh.col[i] + rp_scale * sh.rp[i] + shift;
    if (sh.yaw[i] > 0.0) yaw_scale = std::min(yaw_scale, std::max(0.0, (max_thrust_[i] - base) / sh.yaw[i]));
    if (sh.yaw[i] < 0.0) yaw_scale = std::min(yaw_scale, std::max(0.0, -base / sh.yaw[i]));
  }
  return yaw_scale;
}

}  // namespace swarmbox::flight
