#include "swarmbox/flight/rate_control.hpp"

#include <algorithm>
#include <cmath>

namespace swarmbox::flight {

Vec3 RateControl::Update(const Vec3& rate, const Vec3& rate_sp, const Vec3& angular_accel,
                         double dt_s, bool landed) {
  const Vec3 err = rate_sp - rate;
  // P on error, I from the state, D on the measurement (no kick on setpoint steps), feed-forward.
  Vec3 torque = gains_.p.cwiseProduct(err) + integral_ - gains_.d.cwiseProduct(angular_accel) +
                gains_.ff.cwiseProduct(rate_sp);

  if (!landed && dt_s > 0.0) {
    for (int a = 0; a < 3; ++a) {
      double e = err[a];
      // Anti-windup: do not push further into a saturated actuator direction.
      if ((sat_positive_[static_cast<std::size_t>(a)] && e > 0.0) ||
          (sat_negative_[static_cast<std::size_t>(a)] && e < 0.0)) {
        continue;
      }
      // Integrate less on large errors (a flip or a hard manoeuvre is not a steady offset):
      // the factor falls from 1 at zero error to 0 at 400 deg/s, as PX4 does.
      const double ratio = e / (400.0 * kPi / 180.0);
      const double factor = std::max(0.0, 1.0 - ratio * ratio);
      const double next = integral_[a] + factor * gains_.i[a] * e * dt_s;
      if (std::isfinite(next)) {
        integral_[a] = std::clamp(next, -gains_.integrator_limit[a], gains_.integrator_limit[a]);
      }
    }
  }
  return torque;
}

}  // namespace swarmbox::flight
