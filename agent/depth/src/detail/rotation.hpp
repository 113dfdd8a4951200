// The rotation matrix of a camera pose's quaternion, shared by the depth modules that back-project
// a depth image into the world (clearance, depth_surface, drop_spot).
#pragma once

#include <array>

namespace swarmbox::depth::detail {

// Rotation matrix of a unit quaternion (w x y z), row-major: v_world = R v.
inline std::array<double, 9> RotationMatrix(const std::array<double, 4>& q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

}  // namespace swarmbox::depth::detail
