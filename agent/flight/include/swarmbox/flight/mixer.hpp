// Control allocation from rotor geometry: body torque [N m] and collective thrust [N] -> one
// normalised command per rotor.
//
// The effectiveness matrix B (4 x n) maps rotor thrusts [N] to (roll, pitch, yaw torque, thrust)
// and is built from each rotor's position (body FLU [m]) and spin direction; the allocation is its
// Moore-Penrose pseudo-inverse, computed once at construction. A quad X and a coaxial octo X8 come
// out of the same code: in a coaxial pair both rotors share a column pattern and split the work.
//
// Actuator convention (agreed with the physics engineer): u in [0, 1], rotor speed
// omega = u * max_rot_velocity [rad/s], thrust = motor_constant * omega^2 [N], reaction torque
// about body z = -spin_dir * moment_constant * thrust [N m] (spin_dir +1: counter-clockwise seen
// from above, so the airframe is pushed clockwise). Hence u = sqrt(T / (k * wmax^2)).
//
// Saturation is resolved as PX4 does: roll/pitch and thrust first (thrust shifted, then the
// roll/pitch share scaled down if the spread alone does not fit), yaw gets what is left.
//
//   auto mixer = Mixer::Create(rotors);            // Result<Mixer>: bad geometry is an error
//   MixerOutput out = mixer->Mix(torque_nm, thrust_n);
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {

constexpr std::size_t kMaxRotors = 12;

struct RotorGeometry {
  Vec3 pos_m = Vec3::Zero();        // rotor hub, body FLU [m]
  int spin_dir = 1;                 // +1 counter-clockwise seen from above, -1 clockwise
  double motor_constant = 0.0;      // thrust = motor_constant * omega^2 [N/(rad/s)^2]
  double moment_constant = 0.0;     // reaction torque = moment_constant * thrust [m]
  double max_rot_velocity = 0.0;    // omega at u = 1 [rad/s]
};

struct MixerOutput {
  std::array<double, kMaxRotors> u{};       // normalised commands in [0, 1]; first rotor_count()
  std::array<double, kMaxRotors> thrust_n{};  // per-rotor thrust asked for [N]
  std::array<bool, 3> sat_positive{};       // torque axis could not get all it asked for (+)
  std::array<bool, 3> sat_negative{};       // (-)
  bool thrust_saturated = false;
};

class Mixer {
 public:
  static Result<Mixer> Create(const std::vector<RotorGeometry>& rotors);

  MixerOutput Mix(const Vec3& torque_nm, double thrust_n) const;

  std::size_t rotor_count() const { return n_; }
  double max_thrust_n() const { return max_total_thrust_n_; }
  // Torque the airframe can produce about each body axis around hover with half the rotors at
  // full thrust and half at zero [N m]: the scale of the rate controller's normalised output.
  const Vec3& torque_scale_nm() const { return torque_scale_nm_; }
  // The effectiveness matrix, rows (roll, pitch, yaw torque [N m], thrust [N]) per rotor thrust.
  const Eigen::Matrix<double, 4, Eigen::Dynamic>& effectiveness() const { return b_; }

 private:
  // Each rotor's thrust share of the roll/pitch torque, the yaw torque and the collective [N].
  struct Shares {
    std::array<double, kMaxRotors> rp{};
    std::array<double, kMaxRotors> yaw{};
    std::array<double, kMaxRotors> col{};
  };
  // Mix()'s priorities, in order: the roll/pitch scale, the collective shift that makes it fit,
  // the yaw scale that still fits.
  double RollPitchScale(const Shares& sh) const;
  double CollectiveShift(const Shares& sh, double rp_scale) const;
  double YawScale(const Shares& sh, double rp_scale, double shift) const;
  // alloc_ from b_ (its pseudo-inverse); fails when the geometry has rank < 4.
  Status Allocate();

  std::size_t n_ = 0;
  std::array<double, kMaxRotors> max_thrust_{};
  std::array<double, kMaxRotors> inv_k_wmax2_{};
  Eigen::Matrix<double, 4, Eigen::Dynamic> b_;
  // Allocation columns, per rotor: thrust share of each (roll, pitch, yaw, thrust) unit.
  std::array<std::array<double, 4>, kMaxRotors> alloc_{};
  double max_total_thrust_n_ = 0.0;
  Vec3 torque_scale_nm_ = Vec3::Zero();
};

}  // namespace swarmbox::flight
