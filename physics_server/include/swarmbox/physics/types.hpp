// Small value types shared by the physics API: vectors and quaternions in the SwarmBox frames.
//
// Frames (ARCHITECTURE.md, project conventions): world ENU (x east, y north, z up) [m];
// body FLU (x forward, y left, z up); a Quat (w, x, y, z) rotates body vectors into the world.
#pragma once

#include <cmath>

#include "swarmbox/airframe/vec3.hpp"

namespace swarmbox::physics {

// The airframe model's vector (swarmbox/airframe/vec3.hpp): one type for the file and the world.
using Vec3 = airframe::Vec3;
using airframe::Cross;
using airframe::Dot;
using airframe::Norm;

// Unit quaternion (w, x, y, z), body -> world.
struct Quat {
  double w = 1;
  double x = 0;
  double y = 0;
  double z = 0;

  // Rotation of `yaw_rad` about world +z (ENU: 0 = body x points east, pi/2 = north).
  static Quat FromYaw(double yaw_rad) {
    return {std::cos(yaw_rad / 2), 0, 0, std::sin(yaw_rad / 2)};
  }
  constexpr bool operator==(const Quat&) const = default;
};

// v_world = q * v_body * q^-1.
inline Vec3 Rotate(const Quat& q, const Vec3& v) {
  const Vec3 u{q.x, q.y, q.z};
  const Vec3 t = Cross(u, v) * 2.0;
  return v + t * q.w + Cross(u, t);
}
// v_body = q^-1 * v_world * q.
inline Vec3 RotateInverse(const Quat& q, const Vec3& v) { return Rotate(Quat{q.w, -q.x, -q.y, -q.z}, v); }

// A placement in the world: position [m, ENU] and attitude (body -> world).
struct Pose {
  Vec3 position_m;
  Quat attitude;
};

}  // namespace swarmbox::physics
