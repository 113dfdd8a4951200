#include "camera_trigger.hpp"

#include <cmath>

namespace swarmbox::physics {

bool CameraTrigger::Due(std::size_t drone, const airframe::CameraSpec& spec, bool rate_due, std::int64_t t_ns,
                        const Vec3& position_m) const {
  if (!rate_due) return false;
  if (spec.trigger_distance_m <= 0) return true;
  const Last& last = last_.at(drone);
  if (!last.taken) return true;
  if (std::hypot(position_m.x - last.x_m, position_m.y - last.y_m) >= spec.trigger_distance_m) return true;
  return spec.trigger_interval_max_s > 0 && t_ns - last.t_ns >= std::llround(spec.trigger_interval_max_s * 1e9);
}

void CameraTrigger::Captured(std::size_t drone, std::int64_t t_ns, const Vec3& position_m) {
  last_.at(drone) = {true, t_ns, position_m.x, position_m.y};
}

}  // namespace swarmbox::physics
