// A deliberately simple in-process hover controller for benchmarks and tests: PD on position
// (truth, no estimator), PD on attitude, and an orthogonal mixer built from the airframe's rotor
// list (valid for symmetric X layouts such as x500 and x8_heavy). Not the flight stack.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "swarmbox/physics/airframe.hpp"
#include "swarmbox/physics/sensor_sample.hpp"

namespace swarmbox::physics::testing {

class HoverController {
 public:
  HoverController(const Airframe& af, Vec3 target_m, double extra_mass_kg = 0, double gravity = 9.80665)
      : af_(af), target_(target_m), mass_(af.mass_kg + extra_mass_kg), g_(gravity) {
    for (const RotorSpec& r : af.rotors) {
      sum_x2_ += r.position_m.x * r.position_m.x;
      sum_y2_ += r.position_m.y * r.position_m.y;
    }
  }

  // Fills u (one value per rotor) from the true state.
  void Update(const DroneTruth& t, std::vector<double>* u) const {
    const Vec3 e = target_ - t.position_m;
    const Vec3 a_des{1.0 * e.x - 1.6 * t.velocity_m_s.x, 1.0 * e.y - 1.6 * t.velocity_m_s.y,
                     2.0 * e.z - 2.5 * t.velocity_m_s.z};
    Vec3 thrust_dir{a_des.x, a_des.y, a_des.z + g_};
    const double tilt_limit = 0.35;
    const double horiz = std::hypot(thrust_dir.x, thrust_dir.y);
    if (horiz > tilt_limit * thrust_dir.z) {
      const double s = tilt_limit * thrust_dir.z / horiz;
      thrust_dir.x *= s;
      thrust_dir.y *= s;
    }
    const double norm = Norm(thrust_dir);
    const Vec3 z_des = thrust_dir * (1.0 / norm);
    const Vec3 z_body = Rotate(t.attitude, {0, 0, 1});
    const double total_thrust = mass_ * norm / std::max(0.5, Dot(z_body, z_des));
    // Attitude error as a rotation vector (small angles), in the body frame; yaw held at 0.
    Vec3 err_b = RotateInverse(t.attitude, Cross(z_body, z_des));
    const Vec3 x_body = Rotate(t.attitude, {1, 0, 0});
    err_b.z = -std::atan2(x_body.y, x_body.x);
    const Vec3& I = af_.inertia_kg_m2;
    const Vec3& w = t.body_rates_rad_s;
    const double kp = 40, kd = 12, kp_yaw = 6, kd_yaw = 4;
    const Vec3 torque{I.x * (kp * err_b.x - kd * w.x), I.y * (kp * err_b.y - kd * w.y),
                      I.z * (kp_yaw * err_b.z - kd_yaw * w.z)};
    const double n = static_cast<double>(af_.rotors.size());
    const double km = af_.motor.moment_constant;
    u->resize(af_.rotors.size());
    for (std::size_t r = 0; r < af_.rotors.size(); ++r) {
      const RotorSpec& rs = af_.rotors[r];
      const double s = rs.ccw ? -1.0 : 1.0;  // yaw torque per newton of this rotor's thrust
      double f = total_thrust / n + torque.x * rs.position_m.y / sum_y2_ - torque.y * rs.position_m.x / sum_x2_;
      if (km > 0) f += torque.z * s / (n * km);
      f = std::max(0.0, f);
      const double omega = std::sqrt(f / af_.motor.motor_constant);
      (*u)[r] = std::clamp(omega / af_.motor.max_rot_velocity_rad_s, 0.0, 1.0);
    }
  }

 private:
  const Airframe& af_;
  Vec3 target_;
  double mass_;
  double g_;
  double sum_x2_ = 0, sum_y2_ = 0;
};

}  // namespace swarmbox::physics::testing
